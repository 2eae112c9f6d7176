"""CoGiRo, the 8-cable suspended robot of LIRMM/Tecnalia, as published in CASPR's model files.

Data only (SI units, z up). Source: the CASPR toolbox (darwinlau/CASPR on GitHub),
``data/model_config/models/SCDM/spatial_manipulators/CoGiRo/``:

* ``CoGiRo_cables.xml`` (commit 48462242e83624ec0db315c198e1bdce4fe33f2e):
  ``EXIT_POINTS`` (the ``link 0`` attachments, world frame), ``ANCHORS`` (the
  ``link 1`` attachments, platform frame, ``attachment_reference="joint"``: relative
  to the platform's reference point, not its centre of mass) and the force limits
  ``force_min = 100``, ``force_max = 5000`` N of every cable. CASPR models these
  cables as ``cable_ideal``: straight, with point exits (no pulley radius).
* ``CoGiRo_bodies.xml`` (commit e441b40e182ebce7ca6d8ed0afa9b49722e3ce13):
  ``MASS`` 91.058 kg, ``CENTER_OF_MASS`` (``com_location``, platform frame, from
  the reference point), ``INERTIA`` about the centre of mass in platform axes
  (``inertia ref="com"``; CASPR assembles ``[[Ixx, Ixy, Ixz], [Ixy, Iyy, Iyz],
  [Ixz, Iyz, Izz]]`` from the listed values), ``INITIAL_POSITION`` (``q_initial``:
  the reference point at (0, 0, 2) m, no rotation) and the joint's position range.

The exits span about 15.0 x 11.0 m in x and y and stand about 5.4 m high, two near
each corner. Cables 1, 3, 5, 7 hold the platform at its bottom (anchors at z about
0), cables 2, 4, 6, 8 at its top (z about 1 m), and the bottom ones cross over to
the far side of the platform in x or y.

The shipped scene ``spatial-cogiro`` is this robot with its anchors measured from the centre
of mass (its kinematics and tensions: :mod:`cdpr_exu.statics.kinematics`,
:mod:`cdpr_exu.statics.tension_distribution`).
"""

import numpy as np

#: Cable exit points, world frame, shape (8, 3) [m] (CoGiRo_cables.xml, link 0).
EXIT_POINTS = np.array([
    [-7.1775, -5.4361, 5.3911],
    [-7.4594, -5.1504, 5.3999],
    [-7.3911, 5.1940, 5.3976],
    [-7.1026, 5.4753, 5.4094],
    [7.2398, 5.3759, 5.4093],
    [7.5208, 5.0851, 5.4200],
    [7.4461, -5.2539, 5.3874],
    [7.1608, -5.5342, 5.3973],
])

#: Cable anchors on the platform, platform frame, from its reference point, shape (8, 3) [m] (link 1).
ANCHORS = np.array([
    [0.5032, -0.4928, 0.0],
    [-0.5097, 0.3508, 0.9976],
    [-0.5032, -0.2700, 0.0],
    [0.4960, 0.3561, 0.9996],
    [-0.5032, 0.4928, 0.0],
    [0.4998, -0.3404, 0.9991],
    [0.5021, 0.2750, -0.0007],
    [-0.5045, -0.3463, 0.9976],
])

#: Tension bounds of every cable [N] (force_min, force_max).
MIN_TENSION = 100.0
MAX_TENSION = 5000.0

#: Platform mass [kg].
MASS = 91.058

#: Centre of mass in the platform frame, from the reference point [m] (com_location).
CENTER_OF_MASS = np.array([-0.034, -0.013, 0.264])

#: Inertia tensor about the centre of mass, platform axes [kg m^2].
INERTIA = np.array([
    [36.598, -0.453, 3.012],
    [-0.453, 35.982, -1.539],
    [3.012, -1.539, 25.439],
])

#: Initial pose (r, rotation vector) [m, rad] (q_initial "0 0 2.0 0 0 0": no rotation).
INITIAL_POSE = np.array([0.0, 0.0, 2.0, 0.0, 0.0, 0.0])

#: Range of the reference point's position in CASPR's joint limits [m] (q_min, q_max, translations).
POSITION_RANGE = np.array([[-7.0, -5.0, 0.0], [7.0, 5.0, 5.0]])
