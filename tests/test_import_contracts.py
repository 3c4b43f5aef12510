"""Import contracts of the package layout (docs/architecture.md), read from the source with ``ast``.

Every ``import`` statement of ``stylemotion/**/*.py`` counts, at module level or inside a function alike
(a function-level import is still a dependency, only a later one), including ``TYPE_CHECKING`` blocks.
An import of ``stylemotion.a.b`` is an edge to module ``stylemotion.a.b``; ``from stylemotion.a import b``
is an edge to the submodule ``stylemotion.a.b`` when that is a module, else to ``stylemotion.a`` (the
package ``__init__``). Contracts:

* the core (the kinematics modules at the top level, ``io``, ``config``, ``provenance``) imports no wing
  (search, reconstruct, annotate, morphable, style_example, multilinear), no evaluation and no data set code;
* no wing imports another wing's command module (``command.py``, ``*_command.py``) or another wing's
  package ``__init__`` (a wing's library modules may be used: reconstruct and annotate use search's,
  annotate uses the Morphable Graph's time warping);
* synthesis, models and the viewer never import evaluation;
* no import cycle between modules (packages may depend on each other through different modules: e.g.
  training trains the Morphable Graph and the Morphable Graph's ``stylemotion-train`` path records its run
  with training's run record);
* no private name (``_x``) is imported from another top-level package.

Plus, in fresh interpreters: importing the package (``import stylemotion``: its public API loads on first use), the
commands that read a user's motion, and ``stylemotion.config``, loads no Lightning, and no torch or scikit-learn
(the numpy side); and every console script of pyproject.toml answers ``--help`` and a bad argument without loading
torch, Lightning, scikit-learn, matplotlib or scipy (issue 29: start-up within a second or two; the timings are
the benchmark suite ``startup``'s, never a test's).
"""

from __future__ import annotations

import ast
import json
import re
import subprocess
import sys
from functools import cache
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "stylemotion"

KINEMATICS = {"skeleton", "motion", "geometry", "representation", "ik", "bones"}
CORE = KINEMATICS | {"io", "config", "provenance"}
WINGS = {"search", "reconstruct", "annotate", "morphable", "style_example", "multilinear"}
NEVER_EVALUATION = {"synthesis", "models", "viewer"}


def module_name(path: Path) -> str:
    parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


@cache
def modules() -> dict[str, Path]:
    return {module_name(p): p for p in sorted(PACKAGE.rglob("*.py"))}


def top(module: str) -> str:
    """The top-level package or module of ``stylemotion.<top>...`` (``""`` for ``stylemotion`` itself)."""
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else ""


def is_package(module: str) -> bool:
    return modules()[module].name == "__init__.py"


def imports_of(module: str, source: str | None = None) -> list[tuple[str, str | None, int]]:
    """``(imported module, name imported from it or None, line)`` for every stylemotion import of ``module``."""
    path = modules()[module]
    tree = ast.parse(source if source is not None else path.read_text(), str(path))
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found += [(a.name, None, node.lineno) for a in node.names if a.name.split(".")[0] == "stylemotion"]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = module.split(".") if is_package(module) else module.split(".")[:-1]
                base = base[: len(base) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            if target.split(".")[0] != "stylemotion":
                continue
            for alias in node.names:
                sub = f"{target}.{alias.name}"
                found.append((sub, None, node.lineno) if sub in modules() else (target, alias.name, node.lineno))
    return found


@cache
def graph() -> dict[str, set[str]]:
    return {m: {t for t, _, _ in imports_of(m) if t in modules() and t != m} for m in modules()}


def edges():
    for module in modules():
        for target, name, line in imports_of(module):
            yield module, target, name, line


def where(module: str, line: int) -> str:
    return f"{modules()[module].relative_to(PACKAGE.parent)}:{line}"


def is_command(module: str) -> bool:
    last = module.rsplit(".", 1)[-1]
    return last == "command" or last.endswith("_command")


# -- the contracts, each a list of violations (empty when kept)


def core_violations() -> list[str]:
    banned = WINGS | {"evaluation", "datasets"}
    return [f"{where(m, line)}: core module {m} imports {t}" for m, t, _, line in edges()
            if top(m) in CORE and top(t) in banned]


def wing_violations() -> list[str]:
    out = []
    for m, t, _, line in edges():
        mine, theirs = top(m), top(t)
        if mine not in WINGS or theirs not in WINGS or mine == theirs:
            continue
        what = "command" if is_command(t) else "package init" if is_package(t) else None
        if what:
            out.append(f"{where(m, line)}: {m} imports another wing's {what} {t}")
    return out


def evaluation_violations() -> list[str]:
    return [f"{where(m, line)}: {m} imports {t}" for m, t, _, line in edges()
            if top(m) in NEVER_EVALUATION and top(t) == "evaluation"]


def private_violations() -> list[str]:
    return [f"{where(m, line)}: {m} imports the private name {t}.{name}" for m, t, name, line in edges()
            if name and name.startswith("_") and not name.startswith("__") and top(m) != top(t)]


def cycles(g: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one node (Tarjan, iterative)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found = []
    for root in g:
        if root in index:
            continue
        work = [(root, iter(sorted(g[root])))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        while work:
            node, children = work[-1]
            child = next(children, None)
            if child is not None:
                if child not in index:
                    index[child] = low[child] = len(index)
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(g.get(child, ())))))
                elif child in on_stack:
                    low[node] = min(low[node], index[child])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                component = []
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    component.append(member)
                    if member == node:
                        break
                if len(component) > 1:
                    found.append(sorted(component))
    return found


# -- tests


def test_the_core_imports_no_wing_evaluation_or_data_set_code():
    assert core_violations() == []


def test_no_wing_imports_another_wings_command_or_package_init():
    assert wing_violations() == []


def test_synthesis_models_and_viewer_never_import_evaluation():
    assert evaluation_violations() == []


def test_no_import_cycles_between_modules():
    assert cycles(graph()) == []


def test_no_private_name_crosses_packages():
    assert private_violations() == []


def test_the_contracts_catch_a_bad_import(monkeypatch):
    """Each check fails when its contract is broken (here by imports added to the parsed source)."""
    real = imports_of
    added = {
        "stylemotion.skeleton": "from stylemotion.search.command import search\nfrom stylemotion.datasets import Take",
        "stylemotion.annotate.command": ("from stylemotion.search.command import search\n"
                                         "import stylemotion.style_example"),
        "stylemotion.synthesis.graph": "from stylemotion.evaluation.tables import VARIANCE_KEYS",
        "stylemotion.io.bvh": "from stylemotion.primitives.segmentation import _helper",
    }

    def patched(module, source=None):
        if module in added:
            return real(module, modules()[module].read_text() + "\n" + added[module])
        return real(module, source)

    monkeypatch.setattr(sys.modules[__name__], "imports_of", patched)
    graph.cache_clear()
    try:
        assert any("stylemotion.skeleton imports stylemotion.search.command" in v for v in core_violations())
        assert any("imports stylemotion.datasets" in v for v in core_violations())
        assert any("another wing's command" in v for v in wing_violations())
        assert any("another wing's package init" in v for v in wing_violations())
        assert evaluation_violations()
        assert private_violations()
        # skeleton → representation beside the real representation → skeleton: a cycle
        added["stylemotion.skeleton"] += "\nfrom stylemotion.representation import FRAME_DIM"
        graph.cache_clear()
        assert any({"stylemotion.representation", "stylemotion.skeleton"} <= set(c) for c in cycles(graph()))
    finally:
        graph.cache_clear()


LIGHT = ["stylemotion", "stylemotion.config", "stylemotion.search.command", "stylemotion.annotate.command",
         "stylemotion.reconstruct.command", "stylemotion.datasets.user_motion"]


@pytest.mark.parametrize("module", LIGHT)
def test_reading_a_users_motion_loads_no_lightning(module):
    code = (f"import sys, {module}\n"
            "heavy = sorted(m for m in ('lightning', 'lightning.pytorch', 'pytorch_lightning') if m in sys.modules)\n"
            "print(','.join(heavy))")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "", f"import {module} loads {done.stdout.strip()}"


NUMPY_SIDE = ["stylemotion", "stylemotion.config", "stylemotion.search.command", "stylemotion.reconstruct.command",
              "stylemotion.annotate.command", "stylemotion.datasets.user_motion"]


@pytest.mark.parametrize("module", NUMPY_SIDE)
def test_the_numpy_side_loads_no_torch_or_scikit_learn(module):
    """The kinematics core imports torch inside its torch functions only, and the synthesis and Morphable Graph
    package inits load their names on first use, so reading motion, searching and annotating start without
    torch or scikit-learn (a second or more of start-up)."""
    code = (f"import sys, {module}\n"
            "print(','.join(m for m in ('torch', 'sklearn') if m in sys.modules))")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "", f"import {module} loads {done.stdout.strip()}"


def test_the_public_api_resolves_and_explains_itself():
    """Every name of ``stylemotion.__all__`` loads from its module (not at ``import stylemotion``) and has a docstring
    with its arguments or an example for a newcomer."""
    code = ("import stylemotion, inspect\n"
            "for name in stylemotion.__all__:\n"
            "    obj = getattr(stylemotion, name)\n"
            "    doc = inspect.getdoc(obj) or ''\n"
            "    told = any(w in doc for w in ('Args:', 'Example', 'Attributes:'))\n"
            "    print(name, len(doc), told)")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    rows = [line.split() for line in done.stdout.splitlines()]
    import stylemotion

    assert [r[0] for r in rows] == list(stylemotion.__all__)
    assert {"load", "sample", "evaluate", "walk", "search_motion", "reconstruct_motion", "annotate_motion",
            "view"} <= set(stylemotion.__all__)
    assert all(int(r[1]) > 80 for r in rows), rows
    explained = {r[0] for r in rows if r[2] == "True"}
    assert {"load", "sample", "evaluate", "walk", "search_motion", "reconstruct_motion", "annotate_motion",
            "view"} <= explained


def console_scripts() -> dict[str, str]:
    """``[project.scripts]`` of pyproject.toml: command → ``module:function`` (read without tomllib: Python 3.10)."""
    text = (PACKAGE.parent / "pyproject.toml").read_text()
    block = text.split("[project.scripts]", 1)[1].split("\n[", 1)[0]
    return dict(re.findall(r'^([\w-]+)\s*=\s*"([\w.]+:\w+)"', block, re.M))


#: What no command may load before it prints its help or refuses a bad argument (seconds of start-up each).
HEAVY = ("torch", "lightning", "sklearn", "matplotlib", "scipy")
#: A bad argument per argparse command (an unknown flag after the required arguments); Hydra commands get a key
#: that does not exist.
BAD_ARGUMENTS = {"stylemotion-convert": ["walk.bvh", "walk.npz", "--nosuchflag"],
                 "stylemotion-view": ["walk.bvh", "--out", "viewer", "--nosuchflag"]}

#: Runs an entry point as its console script does, once per argument list (``sys.argv`` = the list, JSON), and
#: prints after each the exit status and which of :data:`HEAVY` were loaded by then.
STARTUP_PROBE = """
import importlib, json, sys
module, function, heavy, *cases = sys.argv[1:]
for argv in map(json.loads, cases):
    sys.argv = [function, *argv]
    try:
        code = getattr(importlib.import_module(module), function)()
    except SystemExit as exc:
        code = exc.code
    sys.stdout.flush()
    print("\\nPROBE " + json.dumps({"exit": code, "heavy": [m for m in heavy.split(",") if m in sys.modules]}))
"""


def startup_probe(entry: str, cases: list[list[str]], cwd: Path) -> list[dict]:
    """``{"exit": status, "heavy": [...]}`` after each argument list of ``cases``, run in turn by one interpreter
    through the entry point ``module:function`` (what a case loads stays loaded for the next)."""
    module, _, function = entry.partition(":")
    done = subprocess.run([sys.executable, "-c", STARTUP_PROBE, module, function, ",".join(HEAVY),
                           *map(json.dumps, cases)], capture_output=True, text=True, timeout=300, cwd=cwd)
    found = [json.loads(ln[len("PROBE "):]) for ln in done.stdout.splitlines() if ln.startswith("PROBE ")]
    assert len(found) == len(cases), f"{entry} {cases}: {len(found)} probe lines; stderr: {done.stderr[-2000:]}"
    return found


def test_every_console_script_is_probed():
    scripts = console_scripts()
    assert len(scripts) >= 14 and all(c.startswith("stylemotion-") for c in scripts), scripts
    assert set(BAD_ARGUMENTS) <= set(scripts)


@pytest.mark.parametrize("command", sorted(console_scripts()))
def test_help_and_a_bad_argument_load_no_torch_lightning_sklearn_matplotlib_or_scipy(command, tmp_path):
    """Issue 29: ``--help`` and a refused argument answer within a second or two because no command loads the
    heavy libraries first: the settings dataclasses Hydra's schemas need live in light modules, package inits load
    their names on first use, the argparse commands import their work after parsing, and Hydra's help computes
    only what its template shows (:func:`stylemotion.cli.skeleton.help_computes_only_what_it_shows`)."""
    entry = console_scripts()[command]
    shown, refused = startup_probe(entry, [["--help"], BAD_ARGUMENTS.get(command, ["nosuchkey=1"])], tmp_path)
    assert shown == {"exit": 0, "heavy": []}, f"{command} --help: {shown}"
    assert refused == {"exit": 2, "heavy": []}, f"{command} --help, then a bad argument: {refused}"
    assert list(tmp_path.iterdir()) == [], f"{command} wrote {sorted(tmp_path.iterdir())}"


def test_the_startup_probe_sees_a_heavy_import(tmp_path):
    """The probe counts what the call imports, not only the entry module (timeit imports scipy.ndimage in ``-s``)."""
    once = ["-n", "1", "-r", "1"]
    quiet, loaded = startup_probe("timeit:main", [[*once, "pass"], [*once, "-s", "import scipy.ndimage", "pass"]],
                                  tmp_path)
    assert quiet["heavy"] == [] and loaded["heavy"] == ["scipy"], (quiet, loaded)
