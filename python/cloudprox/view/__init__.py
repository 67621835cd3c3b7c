"""Interactive 3D views of results: one self-contained HTML file, or a Rerun recording.

A view holds both sides of a query (clouds, or a mesh and a cloud, or a robot at
its configuration and a scene), every point coloured by its collision probability
on a colour bar, the contact patches with their normals and separations, and the
separating surface of the most probable regions (hidden at first). The HTML file
(:func:`write_html`) is drawn by k3d (three.js, its JavaScript inlined: it opens
without a server or the internet, fast even without a GPU: every point is one
WebGL point); turn, zoom, and hover a point for its probability. The points
below ``quiet_below`` are thinned to the density a screen shows of the whole
scene unless ``all_points``. :func:`to_figure` makes the same scene a plotly
figure (``write_html(..., renderer="plotly")``).

k3d and plotly are the optional extra ``cloudprox[view]``, rerun-sdk
``cloudprox[rerun]``.

The package's modules, one job each (every name below is importable from
``cloudprox.view`` itself):

- :mod:`cloudprox.view.scene`: the scene model (:class:`Scene` and its layers)
  and the scenes of a query's result (:func:`collision_scene`,
  :func:`robot_scene`);
- :mod:`cloudprox.view.k3d_renderer`: the k3d plot and its HTML page
  (:func:`to_k3d`, :func:`k3d_page`);
- :mod:`cloudprox.view.plotly_renderer`: the plotly figure (:func:`to_figure`);
- :mod:`cloudprox.view.rerun_renderer`: the Rerun recording (:func:`write_rerun`);
- :mod:`cloudprox.view.output`: the HTML file (:func:`write_html`) and
  :func:`show`.

Examples
--------
>>> import cloudprox as cp
>>> from cloudprox import view
>>> a = cp.PointCloud(cp.synthetic.sample_sphere(300, radius=0.1), sigma=0.002)
>>> result = cp.collide(a, a, pose_b=[[1, 0, 0, 0.19], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]])
>>> scene = view.collision_scene(result, labels=("left", "right"))
>>> [layer.name for layer in scene.points]
['left', 'right']
"""

from cloudprox.view._common import (
    COLORSCALE,
    POINT_PIXELS,
    QUIET_CELLS,
    REGION_COLOR,
    REGION_LABELS,
    SIDE_COLORS,
)
from cloudprox.view.k3d_renderer import k3d_page, to_k3d
from cloudprox.view.output import show, write_html
from cloudprox.view.plotly_renderer import to_figure
from cloudprox.view.rerun_renderer import write_rerun
from cloudprox.view.scene import (
    MeshLayer,
    PointLayer,
    RegionMark,
    Scene,
    collision_scene,
    robot_scene,
    separating_surface,
)

__all__ = [
    "COLORSCALE",
    "POINT_PIXELS",
    "QUIET_CELLS",
    "REGION_COLOR",
    "REGION_LABELS",
    "SIDE_COLORS",
    "MeshLayer",
    "PointLayer",
    "RegionMark",
    "Scene",
    "collision_scene",
    "k3d_page",
    "robot_scene",
    "separating_surface",
    "show",
    "to_figure",
    "to_k3d",
    "write_html",
    "write_rerun",
]
