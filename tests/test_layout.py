"""The package's layers: pure maths and scenes never load Exudyn; controllers and cdpr_exu import no cycle;
only cdpr_exu/cli/ parses arguments and prints, only cdpr_exu/post/ draws."""

import ast
import re
import subprocess
import sys
from pathlib import Path

#: The layers that must stay free of Exudyn (tested without it, reusable on their own).
PURE = ("cdpr_exu.core.geometry", "cdpr_exu.space", "cdpr_exu.core.output", "cdpr_exu.scenes.scene", "cdpr_exu.exits",
        "cdpr_exu.scenes.trajectories", "cdpr_exu.physics.catenary", "cdpr_exu.physics.bending",
        "cdpr_exu.physics.axial_3d", "cdpr_exu.physics.swivel_pulley",
        "cdpr_exu.statics.statics", "cdpr_exu.statics.chain_statics", "cdpr_exu.statics.workspace",
        "cdpr_exu.statics.kinematics", "cdpr_exu.statics.tension_distribution",
        "cdpr_exu.results.result", "cdpr_exu.results.energy", "controllers.ideal_ik", "controllers.tension_aware",
        "controllers.feedback", "controllers.registry", "controllers.ilc")


def test_the_maths_scenes_results_and_controllers_never_load_exudyn():
    code = "import sys\n" + "".join(f"import {m}\n" for m in PURE) + "print('exudyn' in sys.modules)"
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "False"


def test_the_controllers_import_nothing_that_imports_them():
    # controllers/ may use cdpr_exu's maths; the run layer uses the controllers. A controller
    # module that pulled in cdpr_exu.run (or the package's lazy exports) would close a cycle.
    code = ("import sys\nimport controllers.ideal_ik, controllers.tension_aware, controllers.registry, controllers.ilc\n"
            "print(sorted(m for m in sys.modules if m.startswith(('cdpr_exu.run', 'cdpr_exu.studies', "
            "'cdpr_exu.builder'))))")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "[]"


# --------------------------------------------------------------------------- who may do what (issue 24)

ROOT = Path(__file__).resolve().parent.parent
LIBRARY = sorted([*(ROOT / "cdpr_exu").rglob("*.py"), *(ROOT / "controllers").rglob("*.py")])


def _outside(*folders: str) -> list[Path]:
    """The library's modules (cdpr_exu/ and controllers/) outside the given folders of cdpr_exu/."""
    return [path for path in LIBRARY
            if not any((ROOT / "cdpr_exu" / folder) in path.parents for folder in folders)]


def _imported(path: Path) -> set[str]:
    """Every module ``path`` imports, at its top or inside a function (relative imports resolved)."""
    found = set()
    package = ".".join(path.relative_to(ROOT).with_suffix("").parts[:-1])
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = package.rsplit(".", node.level - 1)[0] if node.level else ""
            module = ".".join(part for part in (base, node.module or "") if part)
            found.add(module)
            found.update(f"{module}.{alias.name}" for alias in node.names)
    return found


def _importers(paths: list[Path], *roots: str) -> list[str]:
    return [str(path.relative_to(ROOT)) for path in paths
            if any(name == root or name.startswith(root + ".") for name in _imported(path) for root in roots)]


def test_the_library_and_the_folders_it_checks_are_found():
    assert len(LIBRARY) > 50 and (ROOT / "cdpr_exu" / "cli" / "main.py") in LIBRARY
    assert (ROOT / "cdpr_exu" / "cli" / "main.py") not in _outside("cli")


def test_only_the_command_line_parses_arguments():
    assert _importers(_outside("cli"), "argparse") == []


def test_no_library_module_imports_the_command_line():
    assert _importers(_outside("cli"), "cdpr_exu.cli") == []


def test_library_code_does_not_print():
    # The library returns data (summaries, rest states, estimates) or reports progress through a
    # callback; what the user reads on the console is printed by cdpr_exu/cli/.
    printing = [f"{path.relative_to(ROOT)}:{number}" for path in _outside("cli")
                for number, line in enumerate(path.read_text().splitlines(), 1) if re.search(r"\bprint\(", line)]
    assert printing == []


def test_only_post_draws_figures():
    assert _importers(_outside("post"), "matplotlib", "mpl_toolkits") == []
