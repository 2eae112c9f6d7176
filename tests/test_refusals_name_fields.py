"""Every refusal of a malformed scene names the field it refuses, as a path (issue 12).

Fuzzed over the project's own ``malformed_scene_dicts`` strategy (the paper scene's
plain data with one to three fields broken), with a fixed seed: each refusal, by the
scene validation or by the workspace check that runs before any simulation, must name
a field path such as ``trajectory.radius``, ``pulleys[0].center`` or ``platform.anchors[1]``.
"""

import re

from hypothesis import HealthCheck, given, seed, settings

from cdpr_exu.core.errors import CdprError
from cdpr_exu.scenes.scene import scene_from_dict
from cdpr_exu.statics.workspace import check_reference
from test_input_validation import malformed_scene_dicts, malformed_spatial_scene_dicts

TABLES = (r"(?:name|description|gravity|cable_exit|cable|cables|pulley|pulleys|platform|winch|effects|solver|trajectory"
          r"|dimension|exits|controller_model)")
#: A field path: a scene table with an index or dotted fields (``pulleys[0]``, ``trajectory.radius``,
#: ``platform.anchors[1]``), or a table named as the subject of the refusal (``winch must be a table``),
#: or as what a scene lacks (``scene lacks platform``).
FIELD_PATH = re.compile(r"\b" + TABLES + r"(?:\[\d+\](?:\.[a-z_]+(?:\[\d+\])?)*|(?:\.[a-z_]+(?:\[\d+\])?)+)"
                        + r"|^(?:scene )?" + TABLES + r"\b (?:must|has|is|lacks)"
                        + r"|^scene (?:'[^']*' )?lacks " + TABLES + r"\b")


#: A NumPy repr in a message: ``np.float64(-2.0)``, ``array([1., 2.])``.
NUMPY_REPR = re.compile(r"\bnp\.[a-z_]+\d*\(|\barray\(")


def test_field_path_pattern_accepts_paths_and_rejects_bare_names():
    for text in ("trajectory.radius must be >= 0", "pulleys[0].center", "platform.anchors[1] enters",
                 "gravity must be finite", "winch must be a table, got None", "cables[0] has unknown field(s)",
                 "scene lacks platform: a scene file must give [platform]"):
        assert FIELD_PATH.search(text), text
    for text in ("radius must be >= 0 [m], got -1.0", "anchor [-0.15, -1.9] lies inside the pulley disc"):
        assert not FIELD_PATH.search(text), text


@seed(20261123)
@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(malformed_scene_dicts())
def test_every_refusal_of_a_malformed_scene_names_a_field_path(data):
    try:
        check_reference(scene_from_dict(data))
    except CdprError as err:
        assert FIELD_PATH.search(str(err)), str(err)
        assert not NUMPY_REPR.search(str(err)), str(err)  # plain numbers (issue 23.9)


@seed(20261124)
@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(malformed_spatial_scene_dicts())
def test_every_refusal_of_a_malformed_spatial_scene_names_a_field_path(data):
    """The same for spatial scenes (issue 23): a shipped spatial scene's plain data with one to
    three fields broken, refused by the validation or by the reference check of `cdpr run`."""
    from cdpr_exu.statics.workspace import check_reference

    try:
        scene = scene_from_dict(data)
        if scene.trajectory is not None:
            check_reference(scene)
    except CdprError as err:
        assert FIELD_PATH.search(str(err)), str(err)
        assert not NUMPY_REPR.search(str(err)), str(err)
