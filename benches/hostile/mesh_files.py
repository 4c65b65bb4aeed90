"""Hostile inputs, group 4: mesh files (OBJ, OFF, PLY, STL) in odd but valid forms, broken ones, random
bytes, a directory, a missing file.
"""

from typing import Dict, Optional, Tuple

from hostile.framework import case

# ------------------------------------------------------------------------------------------------
# 4. mesh files
# ------------------------------------------------------------------------------------------------
TETRA_V = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
TETRA_F = "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"
mesh_files: Dict[str, Tuple[str, str, Optional[str], Optional[str]]] = {
    # name: (file name, text, expect, message)
    "obj plain": ("a.obj", TETRA_V + TETRA_F, "correct", None),
    "obj indented": ("a.obj", "  " + TETRA_V.replace("\n", "\n  ") + TETRA_F.replace("\n", "\n\t"), "correct", None),
    "obj tabs and spaces": ("a.obj", TETRA_V.replace(" ", "\t  ") + TETRA_F.replace(" ", " \t "), "correct", None),
    "obj comments after values": (
        "a.obj",
        TETRA_V.replace("\n", " # c\n") + "# a comment\n" + TETRA_F,
        "correct",
        None,
    ),
    "obj crlf": ("a.obj", (TETRA_V + TETRA_F).replace("\n", "\r\n"), "correct", None),
    "obj line continuation": ("a.obj", TETRA_V + "f 1 3 \\\n 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n", "correct", None),
    "obj slashes": (
        "a.obj",
        TETRA_V + "vt 0 0\nvn 0 0 1\nf 1/1/1 3/1/1 2/1/1\nf 1//1 2//1 4//1\nf 1/1 4/1 3/1\nf 2 3 4\n",
        "correct",
        None,
    ),
    "obj negative indices": ("a.obj", TETRA_V + "f -4 -2 -3\nf -4 -3 -1\nf -4 -1 -2\nf -3 -2 -1\n", "correct", None),
    "obj quads": (
        "a.obj",
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
        "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n",
        "correct",
        None,
    ),
    "obj two-vertex face": ("a.obj", TETRA_V + TETRA_F + "f 1 2\n", "warning", "fewer than three"),
    "obj lines and points": ("a.obj", TETRA_V + TETRA_F + "l 1 2\np 3\n", "warning", "line and point"),
    "obj vertex with 2 coords": ("a.obj", "v 0 0\n" + TETRA_V + TETRA_F, "error", "three coordinates"),
    "obj vertex not a number": ("a.obj", "v 0 zero 0\n" + TETRA_V + TETRA_F, "error", "not a number"),
    "obj index 0": ("a.obj", TETRA_V + "f 0 1 2\n", "error", "start at 1"),
    "obj index out of range": ("a.obj", TETRA_V + "f 1 2 9\n", "error", "does not exist"),
    "obj nan vertex": ("a.obj", TETRA_V.replace("v 0 0 1", "v nan 0 1") + TETRA_F, "error", "NaN"),
    "obj huge vertex": ("a.obj", TETRA_V.replace("v 0 0 1", "v 0 0 1e300") + TETRA_F, "error", "1e+30"),
    "obj duplicate triangles": ("a.obj", TETRA_V + TETRA_F + "f 1 3 2\nf 2 3 4\n", "warning", "more than once"),
    "obj degenerate triangle": ("a.obj", TETRA_V + TETRA_F + "f 1 1 2\n", "correct", None),
    "obj all degenerate": ("a.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n", "error", "degenerate"),
    "obj empty": ("a.obj", "", "error", None),
    "obj comments only": ("a.obj", "# nothing\n# here\n", "error", None),
    "obj point cloud": ("a.obj", TETRA_V, "error", "no faces"),
    "obj not a mesh": ("a.obj", "hello world\nthis is not a mesh\n", "error", None),
    "off plain": (
        "a.off",
        "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n",
        "correct",
        None,
    ),
    "off comments and blank lines": (
        "a.off",
        "OFF\n# c\n\n4 4 0\n0 0 0 # v\n1 0 0\n\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n",
        "correct",
        None,
    ),
    "off counts on the OFF line": (
        "a.off",
        "OFF 4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n",
        "correct",
        None,
    ),
    "off colours after faces": (
        "a.off",
        "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1 255 0 0\n3 0 1 3 1 1 1\n3 0 3 2 0 0 0\n3 1 2 3 9 9 9\n",
        "correct",
        None,
    ),
    "off quad": ("a.off", "OFF\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n", "correct", None),
    "off truncated": ("a.off", "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n", "error", "declares"),
    "off bad count": ("a.off", "OFF\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2\n", "error", "declares"),
    "off not a mesh": ("a.off", "hello\n", "error", None),
    "ply ascii": (
        "a.ply",
        "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
        "element face 4\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n"
        "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n",
        "correct",
        None,
    ),
    "ply quad": (
        "a.ply",
        "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
        "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n",
        "correct",
        None,
    ),
    "ply not a mesh": ("a.ply", "hello\n", "error", None),
    "ply vertices only": (
        "a.ply",
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nend_header\n0 0 0\n1 0 0\n0 1 0\n",
        "error",
        None,
    ),
    "stl ascii": (
        "a.stl",
        "solid x\nfacet normal 0 0 1\n outer loop\n  vertex 0 0 0\n  vertex 1 0 0\n  vertex 0 1 0\n endloop\n"
        "endfacet\nendsolid x\n",
        "correct",
        None,
    ),
    "stl not a mesh": ("a.stl", "hello\n", "error", None),
}
for label, (fname, text, expect, message) in mesh_files.items():
    case(
        f"mesh/{label}",
        f"""
        p = write({fname!r}, {text!r})
        m = ts.surfaces.from_mesh(p)
        v, f = m.vertices, m.faces
        # the tetrahedron's, the cube's or one quad's faces, all read (degenerate ones kept apart)
        ok = len(m._good) in (4, 12, 2, 1) and len(v) in (3, 4, 8) and np.all(np.isfinite(v))
    """,
        expect=expect,
        message=message,
    )
for fname in ["a.obj", "a.off", "a.ply", "a.stl"]:
    case(
        f"mesh/random bytes {fname}",
        f"""
        p = write({fname!r}, np.random.default_rng(1).bytes(400), "wb")
        m = ts.surfaces.from_mesh(p)
        ok = False
    """,
        expect="error",
    )
case("mesh/a directory", "m = ts.surfaces.from_mesh(TMP); ok = False", expect="error")
case("mesh/missing file", "m = ts.surfaces.from_mesh(TMP + '/nope.obj'); ok = False", expect="error")
case(
    "mesh/solve on a read tetrahedron",
    f"""
    p = write("t.obj", {TETRA_V + TETRA_F!r})
    m = ts.surfaces.from_mesh(p, normalize=True)
    sol = ts.solve(m, m.grid(41), [m.vertices[0]])
    ok = sane(sol, 3.0)
""",
    expect="returns",
)
