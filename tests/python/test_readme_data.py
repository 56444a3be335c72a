"""Every generated table in README.md equals what its script makes of the committed data
(experiments/results: CSV and benchmark JSON): a README edited by hand, or data regenerated
without rewriting the README, fails here. Each script's own table function is called on the
committed files; nothing is measured."""
import importlib.util
import json
import os
import pathlib
import re

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
README = (ROOT / "README.md").read_text()


def load(relative):
    path = ROOT / relative
    spec = importlib.util.spec_from_file_location(path.stem.replace("-", "_"), path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def block(name):
    match = re.search(rf"<!-- {re.escape(name)}:begin -->\n(.*?)\n<!-- {re.escape(name)}:end -->",
                      README, re.S)
    assert match, f"README.md has no {name} block"
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
    return {"cvode-stiff": stiff.table(stiff.committed_rows()),
            "viewer-speed": load("scripts/viewer-table.py").table(),
            "python-overhead": overhead.table(data),
            "stability-summary": load("scripts/results-tables.py").stability_summary(),
            "work-precision-summary":
                load("scripts/results-tables.py").work_precision_summary(),
            "implicit-damping": load("scripts/results-tables.py").implicit_damping(),
            "scaling-summary": load("scripts/results-tables.py").scaling_summary(),
            "drift-summary": load("scripts/results-tables.py").drift_summary(),
            "atlas-summary": load("scripts/results-tables.py").atlas_summary(),
            "atlas-region": load("scripts/results-tables.py").atlas_region(),
            "atlas-free-summary": load("scripts/results-tables.py").atlas_summary("atlas_free"),
            "experiments-runtime": load("scripts/results-tables.py").experiments_runtime()}


@pytest.mark.parametrize("tables", [speed_tables, integrator_tables, other_tables])
def test_readme_tables_equal_their_data(tables):
    for name, text in tables().items():
        assert block(name) == text, f"README block {name} disagrees with its data: rerun its script"


def test_every_block_in_the_readme_is_checked():
    names = set(re.findall(r"<!-- ([a-z0-9-]+):begin -->", README))
    checked = set(speed_tables()) | set(integrator_tables()) | set(other_tables())
    assert names == checked
