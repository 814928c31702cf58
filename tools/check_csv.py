#!/usr/bin/env python3
"""Check that bench CSV files are well formed: a header, at least one data row, the same
number of fields on every line, and every value of a numeric column (one whose first data
value parses as a number) parses as a number (nan and inf allowed: failed runs).
Usage: tools/check_csv.py FILE.csv...   Exit status 1 if any file is bad."""
import csv
import sys


def is_number(s):
    try:
        float(s)
        return True
    except ValueError:
        return False


def check(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    if not rows:
        return "empty file"
    header, data = rows[0], rows[1:]
    if len(data) == 0:
        return "no data row"
    if len(set(header)) != len(header) or any(not h for h in header):
        return "empty or repeated column name in the header"
    for i, r in enumerate(data, start=2):
        if len(r) != len(header):
            return f"line {i}: {len(r)} fields, header has {len(header)}"
    numeric = [is_number(v) for v in data[0]]
    for i, r in enumerate(data, start=2):
        for c, v in enumerate(r):
            if numeric[c] and not is_number(v):
                return f"line {i}: column '{header[c]}' value '{v}' is not a number"
    return None


def main(paths):
    if not paths:
        print(__doc__)
        return 2
    bad = 0
    for p in paths:
        try:
            err = check(p)
        except OSError as e:
            err = str(e)
        if err:
            bad += 1
            print(f"check_csv: {p}: {err}")
    print(f"check_csv: {len(paths) - bad} of {len(paths)} files well formed")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
