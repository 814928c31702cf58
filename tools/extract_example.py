#!/usr/bin/env python3
"""Write the C code block between <!-- example:begin --> and <!-- example:end --> of a
Markdown file to a .c file, so the README's example is compiled and run as a test."""
import sys

src, dst = sys.argv[1], sys.argv[2]
text = open(src, encoding="utf-8").read()
begin, end = text.index("<!-- example:begin -->"), text.index("<!-- example:end -->")
block = text[begin:end]
code = block[block.index("```c") + 4:block.rindex("```")]
with open(dst, "w", encoding="utf-8") as f:
    f.write(code.lstrip("\n"))
