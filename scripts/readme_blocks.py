"""The README's generated blocks: the text between <!-- NAME:begin --> and <!-- NAME:end -->,
shared by the scripts that write them (speed-tables.py, integrator-table.py, cvode-stiff.py,
viewer-table.py, results-tables.py)."""
import os
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
README = os.path.join(ROOT, "README.md")


def replace_block(text, name, body):
    """`text` with block `name` holding `body`; exits naming the block when it is missing."""
    begin, end = f"<!-- {name}:begin -->", f"<!-- {name}:end -->"
    if begin not in text or end not in text:
        sys.exit(f"README.md has no {begin} ... {end} markers")
    head, rest = text.split(begin, 1)
    _, tail = rest.split(end, 1)
    return head + begin + "\n" + body + "\n" + end + tail


def write_blocks(blocks):
    """Rewrites README.md with every {name: body} of `blocks` (whole or not at all)."""
    with open(README) as f:
        text = f.read()
    for name, body in blocks.items():
        text = replace_block(text, name, body)
    tmp = README + ".tmp"
    with open(tmp, "w") as f:
        f.write(text)
    os.replace(tmp, README)
