"""The package's layers: pure maths and scenes never load Exudyn; controllers and cdpr_exu import no cycle."""

import subprocess
import sys

#: The layers that must stay free of Exudyn (tested without it, reusable on their own).
PURE = ("cdpr_exu.core.geometry", "cdpr_exu.core.output", "cdpr_exu.scenes.scene", "cdpr_exu.scenes.spatial_scene",
        "cdpr_exu.scenes.spatial_trajectories", "cdpr_exu.physics.catenary", "cdpr_exu.physics.bending",
        "cdpr_exu.physics.axial_3d", "cdpr_exu.physics.swivel_pulley", "cdpr_exu.physics.spatial_statics", "cdpr_exu.physics.spatial_kinematics",
        "cdpr_exu.statics.statics", "cdpr_exu.statics.chain_statics", "cdpr_exu.statics.workspace",
        "cdpr_exu.results.result", "cdpr_exu.results.energy", "controllers.ideal_ik", "controllers.tension_aware",
        "controllers.spatial_tension_aware", "controllers.ilc")


def test_the_maths_scenes_results_and_controllers_never_load_exudyn():
    code = "import sys\n" + "".join(f"import {m}\n" for m in PURE) + "print('exudyn' in sys.modules)"
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "False"


def test_the_controllers_import_nothing_that_imports_them():
    # controllers/ may use cdpr_exu's maths; the run layer uses the controllers. A controller
    # module that pulled in cdpr_exu.run (or the package's lazy exports) would close a cycle.
    code = ("import sys\nimport controllers.ideal_ik, controllers.tension_aware, controllers.spatial_tension_aware, controllers.ilc\n"
            "print(sorted(m for m in sys.modules if m.startswith(('cdpr_exu.run', 'cdpr_exu.studies', "
            "'cdpr_exu.builder'))))")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "[]"
