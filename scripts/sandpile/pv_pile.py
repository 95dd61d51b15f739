"""pv_pile.py — run by pvbatch (scripts/sandpile/report.py): a pile at the end of its discharge,
rendered by ParaView from the trajectory's XDMF sidecar with its default reader.

    xvfb-run -a pvbatch scripts/sandpile/pv_pile.py SIDECAR.xdmf OUT.png

The last frame seen along the slot's normal (+x), as the seed's Fig. 4.10 shows her piles: the
spheres (Point Gaussian scaled by radius) sand-coloured, the walls grey with their back faces
culled, so that the slot's near face is not drawn and its far face is the backdrop.  Prints, as
JSON on its last line, the spheres it drew, which the caller checks against the trajectory.
"""
import json
import os
import sys

from paraview import servermanager
from paraview.simple import ExtractCellsByType, OpenDataFile, Render, SaveScreenshot, Show

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))   # scripts/
from pv_display import plain_view, show_spheres  # noqa: E402

SIZE = [800, 420]
FOCUS_Z, HALF_HEIGHT = 0.04, 0.065   # [m] the picture spans z = -0.025 ... 0.105 (the slot's ends in y)
xdmf, png = os.path.abspath(sys.argv[1]), sys.argv[2]
reader = OpenDataFile(xdmf)   # Xdmf3 mis-joins a bare relative name
t = reader.TimestepValues[-1]
spheres = ExtractCellsByType(Input=reader, CellTypes=["Vertex", "Polyvertex"])
walls = ExtractCellsByType(Input=reader, CellTypes=["Quadrilateral"])
view = plain_view(SIZE, [1.0, 1.0, 1.0], t)
show_spheres(spheres, view, [0.80, 0.62, 0.35])
w = Show(walls, view)
w.SetRepresentationType("Surface")
w.ColorArrayName = ["POINTS", ""]
w.AmbientColor = w.DiffuseColor = [0.75, 0.75, 0.75]
w.BackfaceRepresentation = "Cull Backface"
Render(view)   # the first render places the camera on everything: then ours
view.CameraPosition = [-1.0, 0.0, FOCUS_Z]
view.CameraFocalPoint = [0.0, 0.0, FOCUS_Z]
view.CameraViewUp = [0.0, 0.0, 1.0]
view.CameraParallelProjection = 1
view.CameraParallelScale = HALF_HEIGHT
SaveScreenshot(png, view, ImageResolution=SIZE)
spheres.UpdatePipeline(t)
data = servermanager.Fetch(spheres)
n = data.GetNumberOfPoints() if data.IsA("vtkDataSet") else sum(
    data.GetBlock(i).GetNumberOfPoints() for i in range(data.GetNumberOfBlocks()) if data.GetBlock(i))
print(json.dumps({"time": t, "spheres": n}), flush=True)
# pvbatch 5.11 under xvfb sometimes aborts in its own teardown (tests/paraview/pv_probe.py)
os._exit(0)
