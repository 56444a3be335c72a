"""The project's closed sets as the scripts, plots and tests see them: read from the C++ tables
themselves (the X-macros of src/world/integrator_table.h and solvers/linalg/linear_solver.h),
so that no script lists integrators or linear solvers by hand. tests/python/test_recipes.py
checks that these rows equal the ones the compiled module reports.

    python3 scripts/closed_sets.py [integrators|linear-solvers|preconditioners|study-order]
                                   [--field F] [--where F]
prints one row a line, or one field of each (for shell scripts and gnuplot: `integrators
--field name --where explicit`); study-order prints the names in the studies' order."""
import argparse
import os
import re

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
INTEGRATOR_TABLE = os.path.join(ROOT, "src", "world", "integrator_table.h")
LINEAR_SOLVER_TABLE = os.path.join(ROOT, "solvers", "linalg", "linear_solver.h")

# Traits of the linear models (as integrator_table.h's hasStabilityLimit and isAStable).
EXPLICIT_MODELS = ("ForwardEuler", "SymplecticEuler", "RungeKutta4")
A_STABLE_MODELS = ("BackwardEuler", "Bdf2", "Trapezoidal")


def _macro(path, name):
    """The body of `#define NAME(X) ...` with its line continuations joined."""
    with open(path) as f:
        text = f.read()
    match = re.search(rf"#define {name}\(X\)((?:.*\\\n)*.*)", text)
    if not match:
        raise SystemExit(f"closed_sets: no {name} in {path}")
    return match.group(1).replace("\\\n", " ")


def _strings(text):
    """The concatenation of C string literals in `text`."""
    return "".join(re.findall(r'"((?:[^"\\]|\\.)*)"', text))


def integrators():
    """Every row of JELLO_INTEGRATORS, in the table's order, as dicts."""
    body = _macro(INTEGRATOR_TABLE, "JELLO_INTEGRATORS")
    rows = []
    for m in re.finditer(r'X\((\w+),\s*"([^"]*)",\s*"([^"]*)",\s*(\w+),\s*(\w+),\s*(\w+),'
                         r'((?:\s*"(?:[^"\\]|\\.)*")+)\s*\)', body):
        kind, name, file_name, cls, family, model, summary = m.groups()
        rows.append({"kind": kind, "name": name, "file_name": file_name, "class": cls,
                     "family": family, "linear_model": model, "summary": _strings(summary),
                     "explicit": family == "Explicit", "adaptive": model == "Adaptive",
                     "implicit": family != "Explicit" and model != "Adaptive",
                     "fixed_step": model != "Adaptive"})
    if len(rows) != body.count("X("):
        raise SystemExit(f"closed_sets: a row of JELLO_INTEGRATORS lacks a column ({INTEGRATOR_TABLE})")
    return rows


def _name_table(name):
    body = _macro(LINEAR_SOLVER_TABLE, name)
    rows = [{"kind": m.group(1), "name": m.group(2), "summary": _strings(m.group(3))}
            for m in re.finditer(r'X\((\w+),\s*"([^"]*)",((?:\s*"(?:[^"\\]|\\.)*")+)\s*\)', body)]
    if len(rows) != body.count("X("):
        raise SystemExit(f"closed_sets: a row of {name} lacks a column ({LINEAR_SOLVER_TABLE})")
    return rows


def linear_solvers():
    return _name_table("JELLO_LINEAR_SOLVERS")


def preconditioners():
    return _name_table("JELLO_PRECONDITIONERS")


def study_order():
    """The integrators' names as the studies run them: the table's order, adaptive ones last."""
    rows = integrators()
    return [r["name"] for r in rows if not r["adaptive"]] + \
        [r["name"] for r in rows if r["adaptive"]]


def names(family=None):
    """Integrator names in the table's order, of one family when given."""
    return [r["name"] for r in integrators() if family is None or r["family"] == family]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("table", nargs="?", default="integrators",
                        choices=["integrators", "linear-solvers", "preconditioners", "study-order"])
    parser.add_argument("--field", help="print this field of each row, space-separated")
    parser.add_argument("--where", help="only the rows whose FIELD is true (e.g. explicit)")
    args = parser.parse_args()
    if args.table == "study-order":
        print(" ".join(study_order()))
        return
    rows = {"integrators": integrators, "linear-solvers": linear_solvers,
            "preconditioners": preconditioners}[args.table]()
    if args.where:
        rows = [r for r in rows if r.get(args.where)]
    if args.field:
        print(" ".join(str(r[args.field]) for r in rows))
    else:
        for r in rows:
            print("\t".join(str(v) for k, v in r.items() if k != "summary"))


if __name__ == "__main__":
    main()
