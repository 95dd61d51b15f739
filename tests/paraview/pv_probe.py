"""Run by pvbatch (tests/paraview/test_paraview.py): open an XDMF sidecar with ParaView's default
reader and report, as JSON on the last line of stdout, the reader's name, the number of time steps,
and for the middle and the last frame the particles' points, cells and point arrays, the bonds'
line cells and the walls' quadrilaterals; then render the last frame to a PNG on a white
background: spheres (Point Gaussian scaled by radius) blue, walls grey, bonds red, and report
the walls' and the bonds' extent in pixels.

A frame is one multi-piece data set (particles, bonds, walls); the pieces are told apart by
their cells: vertices are particles, lines bonds, quadrilaterals walls.

Usage: pvbatch pv_probe.py SIDECAR.xdmf OUT.png
"""
import json
import os
import sys

from paraview import servermanager
from paraview.simple import (ExtractCellsByType, GetActiveViewOrCreate, OpenDataFile, Render,
                             ResetCamera, SaveScreenshot, Show)

VERTEX, POLY_VERTEX, LINE, POLY_LINE, QUAD = 1, 2, 3, 4, 9
KIND = {VERTEX: "particles", POLY_VERTEX: "particles", LINE: "bonds", POLY_LINE: "bonds",
        QUAD: "walls"}
SIZE = [480, 360]


def pieces(data):
    """The unstructured grids of a frame (a multi-block of multi-pieces, or one grid)."""
    if data.IsA("vtkDataSet"):
        return [data]
    out = []
    it = data.NewIterator()
    it.InitTraversal()
    while not it.IsDoneWithTraversal():
        out.append(it.GetCurrentDataObject())
        it.GoToNextItem()
    return out


def frame_report(data):
    rep = {k: {"points": 0, "cells": 0, "arrays": set()} for k in ("particles", "bonds", "walls")}
    for g in pieces(data):
        if g.GetNumberOfCells() == 0:
            continue
        r = rep[KIND.get(g.GetCellType(0), "walls")]
        r["points"] += g.GetNumberOfPoints()
        r["cells"] += g.GetNumberOfCells()
        pd = g.GetPointData()
        r["arrays"] |= {pd.GetArrayName(i) for i in range(pd.GetNumberOfArrays())}
    for r in rep.values():
        r["arrays"] = sorted(r["arrays"])
    return rep


def pixel_box(view, source, t):
    """The extent in pixels (x0, y0, x1, y1; y from the top) of a source's points at time t."""
    source.UpdatePipeline(t)
    data = servermanager.Fetch(source)
    ren = view.GetRenderer()
    xs, ys = [], []
    for g in pieces(data):
        for i in range(g.GetNumberOfPoints()):
            ren.SetWorldPoint(*g.GetPoint(i), 1.0)
            ren.WorldToDisplay()
            x, y, _ = ren.GetDisplayPoint()
            xs.append(x)
            ys.append(SIZE[1] - y)
    if not xs:
        return None
    return [max(0, int(min(xs))), max(0, int(min(ys))), min(SIZE[0], int(max(xs)) + 1),
            min(SIZE[1], int(max(ys)) + 1)]


xdmf, png = os.path.abspath(sys.argv[1]), sys.argv[2]  # Xdmf3 mis-joins a bare relative name
reader = OpenDataFile(xdmf)
times = list(reader.TimestepValues)
frames = {}
for label, t in (("middle", times[len(times) // 2]), ("last", times[-1])):
    reader.UpdatePipeline(t)
    frames[label] = dict(time=t, **frame_report(servermanager.Fetch(reader)))
view = GetActiveViewOrCreate("RenderView")
view.ViewSize = SIZE
view.UseColorPaletteForBackground = 0
view.Background = [1.0, 1.0, 1.0]
view.OrientationAxesVisibility = 0
view.ViewTime = times[-1]
view.CameraPosition = [1.0, -2.0, 1.2]  # an oblique view, so that floors are not seen edge-on
view.CameraFocalPoint = [0.0, 0.0, 0.0]
view.CameraViewUp = [0.0, 0.0, 1.0]
disp = Show(reader, view)
disp.SetRepresentationType("Point Gaussian")
disp.ScaleByArray = 1
disp.SetScaleArray = ["POINTS", "radius"]
disp.ScaleTransferFunction.Points = [0.0, 0.0, 0.5, 0.0, 1.0, 1.0, 0.5, 0.0]
disp.GaussianRadius = 1.0
disp.ShaderPreset = "Sphere"
disp.ColorArrayName = ["POINTS", ""]  # solid colours: the checks tell the parts by colour
disp.AmbientColor = disp.DiffuseColor = [0.2, 0.3, 0.8]
walls = ExtractCellsByType(Input=reader, CellTypes=["Quadrilateral"])
bonds = ExtractCellsByType(Input=reader, CellTypes=["Line", "Polyline"])
for src, colour in ((walls, [0.6, 0.6, 0.6]), (bonds, [0.9, 0.1, 0.1])):
    d = Show(src, view)
    d.SetRepresentationType("Surface")
    d.ColorArrayName = ["POINTS", ""]
    d.AmbientColor = d.DiffuseColor = colour
    d.LineWidth = 3.0
    d.Ambient, d.Diffuse = 0.6, 0.4  # flat enough that the grey stays grey at any angle
    # wall quadrilaterals face the particles: culling back faces hides the near walls of a box
    d.BackfaceRepresentation = "Cull Backface"
ResetCamera(view)
Render(view)
boxes = {"walls": pixel_box(view, walls, times[-1]), "bonds": pixel_box(view, bonds, times[-1])}
SaveScreenshot(png, view, ImageResolution=SIZE)
print(json.dumps({"reader": reader.GetXMLName(), "times": len(times), "frames": frames,
                  "boxes": boxes}), flush=True)
# pvbatch 5.11 under xvfb sometimes aborts in its own teardown (SIGABRT after everything above is
# done); the report is out and the PNG saved, so leave without the teardown.
os._exit(0)
