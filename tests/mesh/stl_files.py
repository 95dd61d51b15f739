"""STL files of the mesh tests, written from closed-form triangles (reading is admesh's and
LIGGGHTS' job).  The engines read coordinates differently: admesh keeps float32, LIGGGHTS reads
ASCII with atof (double) and binary as float32; write_binary_stl and write_ascii_stl_float32 give
both engines the same values, write_ascii_stl_double gives LIGGGHTS the exact doubles."""
import struct

import numpy as np


def f32(v):
    """v rounded to the nearest float32, as a Python float."""
    return float(np.float32(v))


def write_binary_stl(path, tris):
    """Binary STL (float32 corners; the normal left zero, as both readers ignore it)."""
    with open(path, "wb") as f:
        f.write(b"jdem test mesh".ljust(80, b" "))
        f.write(struct.pack("<I", len(tris)))
        for t in tris:
            f.write(struct.pack("<3f", 0.0, 0.0, 0.0))
            for p in t:
                f.write(struct.pack("<3f", *p))
            f.write(b"\0\0")


def _write_ascii(path, tris, coordinate):
    with open(path, "w") as f:
        f.write("solid wall\n")
        for t in tris:
            f.write(" facet normal 0 0 0\n  outer loop\n")
            for p in t:
                f.write("   vertex %.17g %.17g %.17g\n" % tuple(coordinate(c) for c in p))
            f.write("  endloop\n endfacet\n")
        f.write("endsolid wall\n")


def write_ascii_stl_float32(path, tris):
    """ASCII STL; each coordinate a float32 value with enough digits to be read back exactly by
    admesh (float32) and by LIGGGHTS (atof, double)."""
    _write_ascii(path, tris, f32)


def write_ascii_stl_double(path, tris):
    """ASCII STL; each coordinate the exact double (17 digits), for LIGGGHTS alone."""
    _write_ascii(path, tris, float)
