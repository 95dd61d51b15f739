"""stl_extent.py — the bounding box of an STL file, read by libadmesh (Debian's libadmesh-dev,
the library build/jdem reads meshes with) through ctypes: the deck generator sizes LIGGGHTS'
box around a scene's mesh walls without a second STL reader.

    from scripts.stl_extent import stl_extent
    lo, hi = stl_extent("wall.stl")     # [x, y, z] each, in the file's units

admesh's stl_open fills stl_file.stats.min/max while it reads the facets (admesh 0.98: the
fields below, in this order, from /usr/include/admesh/stl.h).
"""
import ctypes
import ctypes.util


class _Vertex(ctypes.Structure):
    _fields_ = [("x", ctypes.c_float), ("y", ctypes.c_float), ("z", ctypes.c_float)]


class _StatsHead(ctypes.Structure):
    _fields_ = [("header", ctypes.c_char * 81), ("type", ctypes.c_int),
                ("number_of_facets", ctypes.c_int), ("max", _Vertex), ("min", _Vertex)]


class _FileHead(ctypes.Structure):
    _fields_ = [("fp", ctypes.c_void_p), ("facet_start", ctypes.c_void_p),
                ("edge_start", ctypes.c_void_p), ("heads", ctypes.c_void_p),
                ("tail", ctypes.c_void_p), ("M", ctypes.c_int),
                ("neighbors_start", ctypes.c_void_p), ("v_indices", ctypes.c_void_p),
                ("v_shared", ctypes.c_void_p), ("stats", _StatsHead)]


# room for the whole stl_file (the fields above and the rest of stl_stats)
_STL_FILE_BYTES = 4096


def stl_extent(path):
    """([min x, y, z], [max x, y, z]) of the STL file at path; ValueError if admesh cannot read it."""
    lib = ctypes.CDLL(ctypes.util.find_library("admesh") or "libadmesh.so.1")
    buf = ctypes.create_string_buffer(_STL_FILE_BYTES)
    lib.stl_open(buf, path.encode())
    head = _FileHead.from_buffer(buf)
    ok = not lib.stl_get_error(buf) and head.stats.number_of_facets > 0
    lo = [head.stats.min.x, head.stats.min.y, head.stats.min.z]
    hi = [head.stats.max.x, head.stats.max.y, head.stats.max.z]
    lib.stl_close(buf)
    if not ok:
        raise ValueError("admesh cannot read the STL file %s" % path)
    return lo, hi
