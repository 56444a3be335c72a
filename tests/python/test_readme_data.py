"""Every generated block of the documents (README.md and the documents beside what they
describe, scripts/readme_blocks.py's map) equals what its script makes of the committed data
(experiments/results: CSV and benchmark JSON): a document edited by hand, or data regenerated
without rewriting it, fails here. Each script's own function is called on the committed files;
nothing is measured."""
import importlib.util
import json
import os
import pathlib
import re

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]


def load(relative):
    path = ROOT / relative
    spec = importlib.util.spec_from_file_location(path.stem.replace("-", "_"), path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


blocks_map = None


def block(name):
    global blocks_map
    blocks_map = blocks_map or load("scripts/readme_blocks.py")
    text = (ROOT / blocks_map.BLOCKS[name]).read_text()
    match = re.search(rf"<!-- {re.escape(name)}:begin -->\n(.*?)\n<!-- {re.escape(name)}:end -->",
                      text, re.S)
    assert match, f"{blocks_map.BLOCKS[name]} has no {name} block"
    return match.group(1)


def speed_tables():
    m = load("scripts/speed-tables.py")
    with open(m.JSON) as f:
        r = m.Results(json.load(f))
    with open(m.THREADS_JSON) as f:
        threads = m.Results(json.load(f))
    return {"speed-explicit": m.context_line(r) + "\n\n" + m.explicit_table(r),
            "speed-threads": m.threads_table(threads),
            "speed-implicit": m.implicit_table(r),
            "speed-product": m.product_table(r),
            "speed-stiff": m.stiff_table(r)}


def integrator_tables():
    m = load("scripts/integrator-table.py")
    return {"integrators-table": m.table_from_csv(),
            "implicit-steps": m.steps_table_from_json(),
            "crossover": m.crossover_table_from_json(),
            "cvode-second": m.cvode_table_from_json(),
            "kept-factor": m.kept_factor_table_from_json()}


def other_tables():
    stiff = load("scripts/cvode-stiff.py")
    overhead = load("experiments/python/bench_step_overhead.py")
    with open(overhead.JSON) as f:
        data = json.load(f)
    results = load("scripts/results-tables.py")
    return {"cvode-stiff": stiff.table(stiff.committed_rows()),
            "viewer-speed": load("scripts/viewer-table.py").table(),
            "python-overhead": overhead.table(data),
            **{name: make() for name, make in results.BLOCKS.items()}}


@pytest.mark.parametrize("tables", [speed_tables, integrator_tables, other_tables])
def test_readme_tables_equal_their_data(tables):
    for name, text in tables().items():
        assert block(name) == text, f"README block {name} disagrees with its data: rerun its script"


def test_every_block_of_every_document_is_checked():
    blocks = load("scripts/readme_blocks.py")
    checked = set(speed_tables()) | set(integrator_tables()) | set(other_tables())
    assert set(blocks.BLOCKS) == checked
    # And every block marker in the project's documents is one of them, in its own document.
    found = {}
    for path in ROOT.glob("**/*.md"):
        if "build" in path.relative_to(ROOT).parts:
            continue
        for name in re.findall(r"<!-- ([a-z0-9-]+):begin -->", path.read_text()):
            found[name] = str(path.relative_to(ROOT))
    assert found == blocks.BLOCKS
