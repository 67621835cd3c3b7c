"""The MotionBenchMaker planning benchmark harness (``benches/motionbenchmaker.py``).

- :mod:`mbm.fetch`: the ``vamp-planner==0.6.4`` sdist from PyPI (pip, cached,
  SHA-256 checked) and a robot's extracted problems, URDF and meshes;
- :mod:`mbm.scene`: MoveIt planning scenes (boxes, cylinders, spheres; the
  allowed-collision matrix) and motion-plan requests (start, goal) parsed into
  :class:`~mbm.scene.Problem` s;
- :mod:`mbm.sensor`: a scene's simulated Kinect scan and area-sampled cloud
  (:class:`cloudprox.PointCloud` s with their covariances);
- :mod:`mbm.checkers`: python-fcl checkers (exact primitives, voxel map) and the
  motion discretization;
- :mod:`mbm.run`: the planning runs, the tables and the JSON results.
"""
