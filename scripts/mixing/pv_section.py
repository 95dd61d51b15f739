"""pv_section.py — run by pvbatch (scripts/mixing/section_ch5.py): the seed's Fig. 5-4, the
repeated section of a Chapter 5 stream in 3D, rendered by ParaView from a trajectory's XDMF
sidecar with its default reader.

    xvfb-run -a pvbatch scripts/mixing/pv_section.py SIDECAR.xdmf TIME OUT_PREFIX

At the frame nearest TIME [s] (the caller picks one that holds the first section whole and
nothing else), the particles and the bonds, the walls left out: the big spheres red, the small
ones blue, drawn at SPHERE_SCALE of their radius so that the bonds, segments between the centres,
show white between them, as the seed's figure shows them.  Writes OUT_PREFIX_front.png
(looking along +y), OUT_PREFIX_side.png (along -x) and OUT_PREFIX_3d.png (oblique), and prints
as JSON on its last line the particles and bond lines it drew, which the caller checks against
the trajectory.
"""
import json
import os
import sys

from paraview import servermanager
from paraview.simple import (ExtractCellsByType, OpenDataFile, Render, ResetCamera, SaveScreenshot,
                             Show, Threshold)

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))   # scripts/
from pv_display import plain_view, show_spheres  # noqa: E402

SIZE = [600, 600]
SPHERE_SCALE = 0.6
BIG_RADIUS = 0.0225     # [m] between the small (0.015) and the big (0.03) spheres
VIEWS = {"front": ([0.0, -1.0, 0.0], [0.0, 0.0, 1.0]), "side": ([1.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
         "3d": ([1.0, -1.6, 0.9], [0.0, 0.0, 1.0])}


def cells(source, t):
    """The number of cells of a source at time t (over the pieces of a multi-block)."""
    source.UpdatePipeline(t)
    data = servermanager.Fetch(source)
    if data.IsA("vtkDataSet"):
        return data.GetNumberOfCells()
    n, it = 0, data.NewIterator()
    it.InitTraversal()
    while not it.IsDoneWithTraversal():
        n += it.GetCurrentDataObject().GetNumberOfCells()
        it.GoToNextItem()
    return n


def between(source, array, lo, hi):
    """The cells of source whose points all have array within [lo, hi]."""
    f = Threshold(Input=source)
    f.Scalars = ["POINTS", array]
    f.LowerThreshold, f.UpperThreshold = lo, hi
    f.ThresholdMethod = "Between"
    f.AllScalars = 1
    return f


xdmf, when, prefix = os.path.abspath(sys.argv[1]), float(sys.argv[2]), sys.argv[3]
reader = OpenDataFile(xdmf)   # Xdmf3 mis-joins a bare relative name
t = min(reader.TimestepValues, key=lambda x: abs(x - when))
spheres = ExtractCellsByType(Input=reader, CellTypes=["Vertex", "Polyvertex"])
bonds = ExtractCellsByType(Input=reader, CellTypes=["Line", "Polyline"])
big = between(spheres, "radius", BIG_RADIUS, 1.0)
small = between(spheres, "radius", 0.0, BIG_RADIUS)
view = plain_view(SIZE, [0.0, 0.0, 0.0], t)
for src, colour in ((big, [0.85, 0.1, 0.1]), (small, [0.15, 0.3, 0.85])):
    show_spheres(src, view, colour, SPHERE_SCALE)
d = Show(bonds, view)
d.SetRepresentationType("Surface")
d.ColorArrayName = ["POINTS", ""]
d.AmbientColor = d.DiffuseColor = [1.0, 1.0, 1.0]
d.LineWidth = 2.0
for name, (direction, up) in VIEWS.items():
    view.CameraFocalPoint = [0.0, 0.0, 0.0]
    view.CameraPosition = direction
    view.CameraViewUp = up
    view.CameraParallelProjection = int(name != "3d")
    ResetCamera(view)
    Render(view)
    SaveScreenshot("%s_%s.png" % (prefix, name), view, ImageResolution=SIZE)
print(json.dumps({"time": t, "big": cells(big, t), "small": cells(small, t), "bonds": cells(bonds, t)}),
      flush=True)
# pvbatch 5.11 under xvfb sometimes aborts in its own teardown (tests/paraview/pv_probe.py)
os._exit(0)
