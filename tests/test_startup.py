"""Start-up (docs/model.md §7.5): a command imports what it needs. After what `cfmpa dr`, `plan` and
`certify` import and run (the parser of every command, their run_* functions, plan.json's versions,
a certify), a fresh interpreter holds no z3, matplotlib, dask or distributed, and certify no numba,
python-flint or shapely either. The packages spec, impl, report and runs import their modules on
first use (PEP 562 ``__getattr__``, cfmpa.lazy); their ``__all__`` and the type checker's imports
are the same names, each the module's own object; `cfmpa dr` loads its kernels without numba's
registries. Seeded faults: an eager import planted before the check is caught, and so is numba's
own cache load."""

from __future__ import annotations

import ast
import importlib
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from cfmpa.lazy import face_exports

ROOT = Path(__file__).resolve().parents[1]
HEAVY = ("z3", "matplotlib", "dask", "distributed")
#: What certify, which is spec only, does not need either.
PLANNER = ("numba", "flint", "shapely")
LAZY_PACKAGES = {"spec": "cfmpa.spec", "impl": "cfmpa.impl", "report": "cfmpa.report",
                 "runs": "cfmpa.runs"}

TRAJ = "t,left1,left2,right1,right2\n0,0.3,0.8,3.3,0.5\n2,0.3,0.8,3.3,0.5\n"


def _loaded(code: str, prelude: str = "") -> list[str]:
    """The top-level modules of HEAVY + PLANNER that ``prelude`` then ``code`` leave in a fresh
    interpreter's sys.modules."""
    probe = (f"{prelude}\n{code}\nimport json, sys\n"
             f"print(json.dumps(sorted(m for m in {list(HEAVY + PLANNER)!r} if m in sys.modules)))")
    proc = subprocess.run([sys.executable, "-c", probe], cwd=ROOT, capture_output=True, text=True,
                          timeout=120)
    assert proc.returncode == 0, proc.stderr[-2000:]
    return json.loads(proc.stdout.strip().splitlines()[-1])


def _certify(tmp: Path) -> str:
    traj = tmp / "t.csv"
    traj.write_text(TRAJ)
    return ("import contextlib, io\nfrom cfmpa.cli import main\n"
            "with contextlib.redirect_stdout(io.StringIO()):\n"
            f"    assert main(['certify', 'default', '--traj', {str(traj)!r}]) == 0\n")


#: What `cfmpa dr` and `cfmpa plan` import and call before their kernels: the whole parser,
#: their run_* functions, the plan and plan.json's versions.
DR_PLAN = ("from cfmpa.cli import _parser\n_parser()\n"
           "from cfmpa.runs import plan, plan_json, run_dr, run_plan, versions, write_plan\n"
           "versions()\n")


def test_dr_and_plan_load_no_z3_matplotlib_or_dask():
    assert not set(_loaded(DR_PLAN)) & set(HEAVY)


def test_certify_loads_nothing_of_the_planner(tmp_path):
    assert _loaded(_certify(tmp_path)) == []


#: What `cfmpa dr` imports of plan.py and the contracts (not plan.json's versions: shapely's).
CONTRACTS = ("from cfmpa.cli import _parser\n_parser()\n"
             "from cfmpa.runs import plan, run_dr, run_plan\n"
             "import cfmpa.runs._contracts, cfmpa.spec._triples\n")


def test_the_contracts_modules_load_no_shapely_until_a_check_runs():
    # plan.py imports the contracts (runs._contracts, spec._triples) at its top, and `cfmpa dr`
    # imports plan.py; the postcondition, which needs shapely, is imported by its check.
    assert "shapely" not in _loaded(CONTRACTS)
    # Seeded fault: spec._triples importing the postcondition at its top, as it did.
    assert "shapely" in _loaded(CONTRACTS, "import cfmpa.spec._triples, cfmpa.spec._builtdr_post")


def test_seeded_fault_an_eager_import_is_caught(tmp_path):
    # versions() as it was: it imported z3 for its version string
    planted = "import z3\n"
    assert "z3" in _loaded(DR_PLAN, planted)
    # runs/__init__.py as it was: every module imported with the package
    eager = "import cfmpa.runs\nfor n in cfmpa.runs.__all__: getattr(cfmpa.runs, n)\n"
    assert "numba" in _loaded(_certify(tmp_path), eager)


def test_z3_version_without_z3_is_z3s_own():
    import z3

    from cfmpa.runs._plan import z3_version
    assert z3_version() == z3.get_version_string()


def _type_checking_names(path: Path) -> dict[str, tuple[str, str]]:
    """name -> (module, name there) of the imports under ``if TYPE_CHECKING:``."""
    out: dict[str, tuple[str, str]] = {}
    for node in ast.parse(path.read_text()).body:
        if isinstance(node, ast.If) and getattr(node.test, "id", None) == "TYPE_CHECKING":
            for imp in node.body:
                assert isinstance(imp, ast.ImportFrom) and imp.level == 1
                for a in imp.names:
                    out[a.asname or a.name] = ("." + str(imp.module), a.name)
    return out


@pytest.mark.parametrize("folder", sorted(LAZY_PACKAGES))
def test_lazy_packages_keep_their_public_names(folder):
    pkg = importlib.import_module(LAZY_PACKAGES[folder])
    face = ROOT / folder / "__init__.py"
    # A face of one list (cfmpa.lazy.lazy_face) or of a table beside its __all__.
    table = pkg._EXPORTS if "_EXPORTS" in vars(pkg) else face_exports(face)
    lazy = {name: tuple(where.split(":")) for name, where in table.items()}
    assert _type_checking_names(ROOT / folder / "__init__.py") == lazy
    assert set(pkg.__all__) <= set(lazy)
    for name, (module, attr) in lazy.items():
        assert getattr(pkg, name) is getattr(importlib.import_module(module, pkg.__name__), attr)
    assert set(pkg.__all__) <= set(dir(pkg))
    with pytest.raises(AttributeError):
        pkg.no_such_name  # noqa: B018


# --- each command, run whole, imports only what it uses ----------------------------------------

#: Modules no command below needs unless it says so: the solvers, the report, the cluster, the
#: bag reader, the store, the exact re-decision.
NOT_NEEDED = ("z3", "cvc5", "matplotlib", "jinja2", "dask", "distributed", "rosbags", "sqlite3",
              "zarr", "numcodecs", "flint", "sympy", "crosshair")
#: What each command may load of NOT_NEEDED (and what the trajectory commands must not load of
#: the planner), with the argv it runs; {tmp} is a folder of the test's, holding t.csv and a plan.
COMMANDS: dict[str, tuple[list[str], set[str], tuple[str, ...]]] = {
    "scenarios": (["scenarios"], set(), ("numba", "shapely")),
    # (numpy comes with every command: the shared parser reads spec's variant table.)
    "docs": (["docs"], set(), ("numba", "shapely")),
    # dr checks nothing: shapely (the spec's geometry, for the contracts) stays out too.
    "dr": (["dr", "{small}", "--out", "{tmp}/dr"], set(), ("shapely",)),
    "plan": (["plan", "{small}", "--out", "{tmp}/plan"], {"flint"}, ()),
    "check": (["check", "{small}", "--dr", "{tmp}/plan/dr.npy", "--plan",
               "{tmp}/plan/plan.json"], {"flint"}, ()),
    "certify": (["certify", "default", "--traj", "{tmp}/t.csv"], set(), PLANNER),
    "simulate": (["simulate", "default", "--traj", "{tmp}/t.csv", "--out", "{tmp}/log.csv"],
                 set(), PLANNER),
    "monitor": (["monitor", "default", "--traj", "{tmp}/t.csv", "--log", "{tmp}/log.csv"],
                set(), PLANNER),
}


def _command_modules(argv: list[str], prelude: str = "") -> tuple[int, set[str]]:
    """(exit code, top-level modules of NOT_NEEDED + PLANNER + numpy loaded) of `cfmpa argv`
    run whole in a fresh interpreter, after ``prelude``."""
    watch = list(NOT_NEEDED + PLANNER + ("numpy",))
    probe = (f"{prelude}\nimport contextlib, io, json, sys\nfrom cfmpa.cli import main\n"
             "with contextlib.redirect_stdout(io.StringIO()), "
             "contextlib.redirect_stderr(io.StringIO()):\n"
             f"    code = main({argv!r})\n"
             f"print(json.dumps([code, sorted(m for m in {watch!r} if m in sys.modules)]))")
    proc = subprocess.run([sys.executable, "-c", probe], cwd=ROOT, capture_output=True, text=True,
                          timeout=300)
    assert proc.returncode == 0, proc.stderr[-2000:]
    code, mods = json.loads(proc.stdout.strip().splitlines()[-1])
    return code, set(mods)


@pytest.fixture(scope="module")
def workdir(tmp_path_factory) -> Path:
    import factory

    tmp = tmp_path_factory.mktemp("startup")
    (tmp / "t.csv").write_text(TRAJ)
    (tmp / "small.toml").write_text(factory.toml(factory.doc()))
    return tmp


def _argv(command: str, workdir: Path) -> list[str]:
    return [a.format(tmp=workdir, small=workdir / "small.toml") for a in COMMANDS[command][0]]


@pytest.mark.parametrize("command", list(COMMANDS))
def test_each_command_imports_only_what_it_uses(command, workdir):
    _, allowed, never = COMMANDS[command]
    # check reads plan's folder, monitor simulate's log: made first (by the same commands).
    for needs, made in (("check", "plan/plan.json"), ("monitor", "log.csv")):
        if command == needs and not (workdir / made).exists():
            assert _command_modules(_argv("plan" if needs == "check" else "simulate",
                                          workdir))[0] == 0
    code, loaded = _command_modules(_argv(command, workdir))
    assert code == 0, (command, code)
    assert not (loaded & set(NOT_NEEDED)) - allowed, (command, sorted(loaded))
    assert not loaded & set(never), (command, sorted(loaded))


def test_seeded_faults_an_eager_bag_reader_or_exact_import_is_caught(workdir):
    # The bag reader importing sqlite3 at its top, as it did (with the parser's budgets read
    # from the trajectory runs, it came with every command); plan.py importing the exact
    # re-decision at its top, as it did: python-flint comes with `cfmpa dr`.
    for planted, module in (("import cfmpa.runs._trajectory_runs, sqlite3", "sqlite3"),
                            ("import cfmpa.spec._exact", "flint")):
        code, loaded = _command_modules(_argv("dr", workdir), planted)
        assert code == 0 and module in loaded
        assert module in set(NOT_NEEDED) - COMMANDS["dr"][1]


#: What `cfmpa dr` no longer loads with its kernels (docs/model.md §7.5): numba's registries
#: (imported by numba's refresh before a cache load; a load needs only the runtime) and numba's
#: array implementation (imported by the cache load of a kernel that allocates).
NUMBA_REGISTRIES = ("numba.cpython.unicode", "numba.typed.typeddict", "numba.np.arrayobj")


def _dr_numba_modules(workdir: Path, prelude: str = "") -> tuple[str, set[str]]:
    """(the `variant` line, NUMBA_REGISTRIES loaded) of `cfmpa dr` run whole in a fresh
    interpreter with the fast kernels (compiled first if the cache is cold)."""
    probe = (f"{prelude}\nimport contextlib, io, json, sys\nfrom cfmpa.cli import main\n"
             "out = io.StringIO()\nwith contextlib.redirect_stdout(out):\n"
             f"    assert main({_argv('dr', workdir)!r}) == 0\n"
             "line = next(x for x in out.getvalue().splitlines() if x.startswith('variant'))\n"
             f"print(json.dumps([line, [m for m in {list(NUMBA_REGISTRIES)!r} "
             "if m in sys.modules]]))")
    env = dict(os.environ, CFMPA_KERNEL_COMPILE="wait")
    proc = subprocess.run([sys.executable, "-c", probe], cwd=ROOT, env=env, capture_output=True,
                          text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr[-2000:]
    line, mods = json.loads(proc.stdout.strip().splitlines()[-1])
    return line, set(mods)


def test_dr_loads_its_kernels_without_numbas_registries(workdir):
    line, loaded = _dr_numba_modules(workdir)
    assert "(fast kernel)" in line and not loaded, (line, sorted(loaded))


def test_seeded_fault_numbas_own_cache_load_is_caught(workdir):
    # The kernels' cache as numba gives it (no lean loads): the registries come with `dr`.
    line, loaded = _dr_numba_modules(
        workdir, "import cfmpa.impl._kernel_cache as k\nk.lean_loads = lambda mod: 0\n")
    assert "(fast kernel)" in line and set(NUMBA_REGISTRIES) <= loaded
