"""The documents' generated blocks: the text between <!-- NAME:begin --> and <!-- NAME:end -->
in the README or in the document beside what it describes, shared by the scripts that write
them (speed-tables.py, integrator-table.py, cvode-stiff.py, viewer-table.py, results-tables.py)
and by the test that checks them against the committed data (tests/python/test_readme_data.py).
BLOCKS says which document holds each block."""
import os
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
README = os.path.join(ROOT, "README.md")

# Each generated block and the document (relative to the project) that holds it.
BLOCKS = {
    "findings": "README.md",
    "integrator-list": "README.md",
    "ci-time": "README.md",
    "contact-newton": "README.md",
    "contact-speed": "README.md",
    "projective-speed": "README.md",
    "experiments-runtime": "experiments/README.md",
    "stability-summary": "experiments/README.md",
    "work-precision-summary": "experiments/README.md",
    "implicit-damping": "experiments/README.md",
    "drift-summary": "experiments/README.md",
    "scaling-summary": "experiments/README.md",
    "atlas-summary": "experiments/README.md",
    "atlas-region": "experiments/README.md",
    "atlas-free-summary": "experiments/README.md",
    "atlas-contact-summary": "experiments/README.md",
    "atlas-slide-summary": "experiments/README.md",
    "slide-steps": "experiments/README.md",
    "atlas-trace-summary": "experiments/README.md",
    "integrators-table": "solvers/README.md",
    "implicit-steps": "solvers/README.md",
    "crossover": "solvers/README.md",
    "cvode-second": "solvers/README.md",
    "cvode-stiff": "solvers/README.md",
    "speed-explicit": "experiments/bench/README.md",
    "speed-threads": "experiments/bench/README.md",
    "speed-implicit": "experiments/bench/README.md",
    "speed-product": "experiments/bench/README.md",
    "kept-factor": "experiments/bench/README.md",
    "speed-stiff": "experiments/bench/README.md",
    "viewer-speed": "viewer/README.md",
    "python-overhead": "experiments/python/README.md",
}


def document(name):
    """The path of the document holding block `name`."""
    return os.path.join(ROOT, BLOCKS[name])


def documents():
    """Every document that holds a generated block."""
    return sorted({os.path.join(ROOT, path) for path in BLOCKS.values()})


def replace_block(text, name, body, path="README.md"):
    """`text` with block `name` holding `body`; exits naming the block when it is missing."""
    begin, end = f"<!-- {name}:begin -->", f"<!-- {name}:end -->"
    if begin not in text or end not in text:
        sys.exit(f"{os.path.relpath(path, ROOT)} has no {begin} ... {end} markers")
    head, rest = text.split(begin, 1)
    _, tail = rest.split(end, 1)
    return head + begin + "\n" + body + "\n" + end + tail


def write_blocks(blocks):
    """Rewrites each document holding a block of {name: body} (each whole or not at all)."""
    by_path = {}
    for name, body in blocks.items():
        by_path.setdefault(document(name), {})[name] = body
    for path, mine in by_path.items():
        with open(path) as f:
            text = f.read()
        for name, body in mine.items():
            text = replace_block(text, name, body, path)
        tmp = path + ".tmp"
        with open(tmp, "w") as f:
            f.write(text)
        os.replace(tmp, path)
