"""The README's Python quick start (between <!-- python:begin --> and <!-- python:end -->) runs
as it is, in a fresh interpreter (it asserts its own results)."""
import os
import subprocess
import sys


def readme_block(path):
    text = open(path, encoding="utf-8").read()
    a, b = text.index("<!-- python:begin -->"), text.index("<!-- python:end -->")
    block = text[a:b]
    return block[block.index("```python") + len("```python"):block.rindex("```")]


def test_readme_python_quick_start(readme_path):
    code = readme_block(readme_path)
    assert "solve_ivp" in code and len(code.strip().splitlines()) <= 20
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=dict(os.environ),
                         timeout=120)
    assert out.returncode == 0, out.stderr
    assert "sliding_entry" in out.stdout
