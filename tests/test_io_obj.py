"""The OBJ reader (``cloudprox.io.read_mesh`` on ``.obj``): forms, indices, errors."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

import cloudprox as cp

CUBE = """\
# unit cube, quads, counter-clockwise seen from outside
mtllib cube.mtl
o cube
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
v 0 0 1
v 1 0 1
v 1 1 1
v 0 1 1
vn 0 0 -1
s off
usemtl grey
f 1 4 3 2
f 5 6 7 8
f 1 2 6 5
f 2 3 7 6
f 3 4 8 7
f 4 1 5 8
"""

TETRA = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"


def _write(tmp_path: Path, text: str, name: str = "mesh.obj") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def test_obj_cube_of_quads(tmp_path: Path) -> None:
    mesh = cp.io.read_mesh(_write(tmp_path, CUBE))
    assert mesh.faces.shape == (12, 3)
    assert mesh.vertices.shape == (8, 3)
    assert mesh.volume == pytest.approx(1.0)
    assert mesh.area == pytest.approx(6.0)
    assert mesh.is_closed
    assert mesh.is_convex()


def test_obj_slash_forms_and_ignored_statements(tmp_path: Path) -> None:
    text = (
        "g part\nv 0 0 0\nv 1 0 0 1.0\nv 0 1 0\nv 0 0 1  # apex\n"
        "vt 0 0\nvt 1 0\nvt 0 1\nvn 0 0 1\n"
        "f 1/1 3/3 2/2\nf 1//1 2//1 4//1\nf 1/1/1 4/2/1 3/3/1\nf 2 3 \\\n  4\n"
    )
    mesh = cp.io.read_mesh(_write(tmp_path, text))
    np.testing.assert_array_equal(mesh.faces, [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    assert mesh.is_closed
    assert mesh.volume == pytest.approx(1 / 6)


def test_obj_negative_indices(tmp_path: Path) -> None:
    text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\nv 0 0 1\nf -4 -1 -3\nf 2/1 -2//1 -1/1/1\n"
    mesh = cp.io.read_mesh(_write(tmp_path, text))
    np.testing.assert_array_equal(mesh.faces, [[0, 1, 2], [0, 3, 1], [1, 2, 3]])


def test_obj_degenerate_faces_dropped_visibly(tmp_path: Path) -> None:
    path = _write(tmp_path, TETRA + "f 1 2 3\nf 1 1 2\nf 2 4 4 3\n")
    with pytest.warns(cp.DegenerateFacesWarning, match=r"dropped 2 degenerate face"):
        mesh = cp.io.read_mesh(path)
    # the quad 2 4 4 3 fans into (2 4 4), dropped, and (2 4 3), kept
    np.testing.assert_array_equal(mesh.faces, [[0, 1, 2], [1, 3, 2]])


def test_obj_lines_and_points_are_ignored(tmp_path: Path) -> None:
    mesh = cp.io.read_mesh(_write(tmp_path, TETRA + "l 1 2\np 3\nf 1 2 3\n"))
    np.testing.assert_array_equal(mesh.faces, [[0, 1, 2]])


@pytest.mark.parametrize(
    ("text", "problem"),
    [
        (TETRA + "v 1 2 x\nf 1 2 3\n", r"line 5: malformed number"),
        (TETRA + "v 1 2\nf 1 2 3\n", r"line 5: a vertex needs 3 to 7 numbers"),
        (TETRA + "v 1 nan 2\nf 1 2 3\n", r"line 5: non-finite vertex coordinate"),
        (TETRA + "f 1 2 3\nf 1 2 9\n", r"line 6: face vertex index 9 out of range"),
        (TETRA + "f 1 2 -5\n", r"line 5: face vertex index -5 out of range"),
        (TETRA + "f 1 0 2\n", r"line 5: face vertex index 0"),
        (TETRA + "f 1 2/x 3\n", r"line 5: malformed face vertex \"2/x\""),
        (TETRA + "f 1 2\n", r"line 5: a face needs at least 3 vertices, found 2"),
        ("", r"no faces"),
        ("# nothing\n" + TETRA, r"no faces"),
        (TETRA + "f 1 1 2\n", r"no faces: all 1 triangles repeat a vertex"),
    ],
)
def test_obj_errors_name_file_line_and_problem(tmp_path: Path, text: str, problem: str) -> None:
    path = _write(tmp_path, text, "bad.obj")
    with pytest.raises(cp.FormatError, match=re.escape(str(path)) + ".*" + problem):
        cp.io.read_mesh(path)
