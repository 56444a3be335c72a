"""The closed sets are tables, and src/ARCHITECTURE.md's recipes are true (house style: "a
closed set is one table"). scripts/closed_sets.py reads the C++ tables; the compiled module
reports the same rows. No file outside the recipes lists integrators, linear solvers or
preconditioners by hand (three or more of them named in its code is a list), and each
recipe's file count is the count of the files it names, which for an obstacle are exactly the
code files that name one."""
import importlib.util
import pathlib
import re
import subprocess

import jello

ROOT = pathlib.Path(__file__).resolve().parents[2]
ARCHITECTURE = (ROOT / "src" / "ARCHITECTURE.md").read_text()


def load(relative):
    path = ROOT / relative
    spec = importlib.util.spec_from_file_location(path.stem.replace("-", "_"), path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


closed_sets = load("scripts/closed_sets.py")
INTEGRATORS = closed_sets.integrators()
NAMES = [r["name"] for r in INTEGRATORS]
KINDS = {r["kind"]: r["name"] for r in INTEGRATORS}

# Files that may name many integrators: where their classes are declared (each class says its
# own kind) and the picks of the studies and the benchmarks, each a choice with its reason
# written beside it (experiments/studies/study_integrators.h; the benchmarks measure chosen
# configurations).
DEFINE_OR_PICK = {
    "src/world/integrator_table.h",
    "solvers/methods/explicit_integrators.h",
    "solvers/methods/newton_integrators.h",
    "experiments/studies/study_integrators.cpp",
    "experiments/bench/benchmarks_implicit.cpp",
    "experiments/bench/benchmarks_one_second.cpp",
    # The reference, and the quick run's picks (Newton's first- and second-order steps).
    "experiments/python/energy_over_time.py",
    # The reference and implicit's variants ('projective' there is the preconditioner).
    "scripts/integrator-table.py",
    # The trace chart's picks: two first-order steps that lose the rebound (backward Euler's and
    # projective's) and a second-order one that keeps part of it (BDF2).
    "experiments/plots/atlas_trace.gp",
}


def code_files():
    listed = subprocess.run(["git", "ls-files", "*.cpp", "*.h", "*.py", "*.gp", "*.sh"],
                            cwd=ROOT, check=True, capture_output=True, text=True).stdout.split()
    return [f for f in listed if not f.startswith(("tests/", "experiments/results/"))]


def without_comments(path, text):
    if path.endswith((".cpp", ".h")):
        return re.sub(r"//[^\n]*", "", text)
    return re.sub(r"(^|\s)#[^\n]*", r"\1", text)


def strings(text):
    return re.findall(r'"([^"\n]*)"', text) + re.findall(r"'([^'\n]*)'", text)


def named(path, text, names, enumerators):
    """The members of a set that the code of `path` names: as enumerators (C++) or as strings
    made only of member names ("rk4", "euler symplectic rk4")."""
    code = without_comments(path, text)
    found = {enumerators[k] for k in re.findall(r"\b(?:IntegratorKind|LinearSolverKind|"
                                                 r"PreconditionerKind)::(\w+)", code)
             if k in enumerators}
    for s in strings(code):
        words = [w for w in re.split(r"[\s,]+", s) if w]
        if words and all(w in names for w in words):
            found.update(words)
    return found


def lists(names, enumerators, allowed):
    offenders = {}
    for path in code_files():
        text = (ROOT / path).read_text(errors="replace")
        hit = named(path, text, names, enumerators)
        if len(hit) >= 3 and path not in allowed:
            offenders[path] = sorted(hit)
    return offenders


def test_the_scripts_read_the_same_integrator_table_as_the_module():
    module = jello.integrator_table()
    keys = ["name", "file_name", "family", "linear_model", "summary", "explicit", "adaptive"]
    assert [{k: r[k] for k in keys} for r in INTEGRATORS] == \
        [{k: r[k] for k in keys} for r in module]
    assert list(jello.integrators()) == NAMES


def test_no_file_lists_integrators_by_hand():
    assert lists(set(NAMES), KINDS, DEFINE_OR_PICK) == {}


def test_no_file_lists_linear_solvers_or_preconditioners_by_hand():
    for table in (closed_sets.linear_solvers(), closed_sets.preconditioners()):
        names = {r["name"] for r in table}
        enumerators = {r["kind"]: r["name"] for r in table}
        # The table, and the solver that implements each row.
        allowed = {"solvers/linalg/linear_solver.h", "solvers/linalg/linear_solver.cpp"}
        assert lists(names, enumerators, allowed) == {}


def test_the_check_finds_a_list_written_by_hand():
    text = 'for (auto k : {IntegratorKind::Euler, IntegratorKind::RK4}) run("implicit");'
    assert named("x.cpp", text, set(NAMES), KINDS) == {"euler", "rk4", "implicit"}
    assert named("x.gp", 'integrators = "euler symplectic rk4"', set(NAMES), KINDS) == \
        {"euler", "symplectic", "rk4"}
    assert named("x.py", '# "euler symplectic rk4"\nprint("the implicit step")', set(NAMES),
                 KINDS) == set()


NUMBERS = {"four": 4, "five": 5, "six": 6, "seven": 7, "eight": 8, "nine": 9, "ten": 10,
           "eleven": 11, "twelve": 12, "thirteen": 13, "fourteen": 14, "fifteen": 15}


def recipe(title):
    """(the file count the recipe states, the paths of its numbered steps in order)."""
    section = ARCHITECTURE.split(f"## {title}\n", 1)[1].split("\n## ", 1)[0]
    count = NUMBERS[re.match(r"\s*(\w+)", section).group(1).lower()]
    steps = re.findall(r"^\d+\. `([^`]+)`", section, re.M)
    return count, steps


def test_the_integrator_recipe_names_as_many_files_as_it_says():
    count, steps = recipe("How to add an integrator")
    assert len(steps) == count == 6
    for path in steps:
        if "<" not in path:
            assert (ROOT / path).exists(), path
    # What the recipe's fixed files must hold for it to be true.
    assert "JELLO_INTEGRATORS" in (ROOT / "src/world/integrator_table.h").read_text()
    assert "JELLO_INTEGRATORS" in (ROOT / "solvers/integrator_factory.cpp").read_text()


def test_the_obstacle_recipe_names_exactly_the_files_that_name_an_obstacle():
    count, steps = recipe("How to add an obstacle")
    assert len(steps) == count
    assert all((ROOT / path).exists() for path in steps)
    # The last obstacles added: every C++ or Python file naming them is a step of the recipe
    # (the scripts that build scenes with them only use them).
    for obstacle in ("Cone", "Spiral"):
        pattern = re.compile(rf"\b({obstacle}|{obstacle.lower()})\b")
        naming = {path for path in code_files() if path.endswith((".cpp", ".h", ".py"))
                  and pattern.search(without_comments(path, (ROOT / path).read_text()))}
        assert naming == set(steps), obstacle
