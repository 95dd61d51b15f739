"""pv_display.py — the ParaView settings the pvbatch scripts share (scripts/mixing/pv_section.py,
scripts/sandpile/pv_pile.py): a plain view, and spheres drawn from an XDMF sidecar's points as
ParaView's sphere-shaded Point Gaussians scaled by their `radius` array (docs/output.md).

Imported inside pvbatch: the caller puts this folder on sys.path.
"""
from paraview.simple import GetActiveViewOrCreate, Show


def plain_view(size, background, time):
    """The render view at `time` [s]: `size` pixels, a flat `background`, no axes triad."""
    view = GetActiveViewOrCreate("RenderView")
    view.ViewSize = size
    view.UseColorPaletteForBackground = 0
    view.Background = background
    view.OrientationAxesVisibility = 0
    view.ViewTime = time
    return view


def show_spheres(source, view, colour, scale=1.0):
    """Draw source's points as spheres of `scale` times their radius, in one solid colour."""
    d = Show(source, view)
    d.SetRepresentationType("Point Gaussian")
    d.ScaleByArray = 1
    d.SetScaleArray = ["POINTS", "radius"]
    d.ScaleTransferFunction.Points = [0.0, 0.0, 0.5, 0.0, 1.0, scale, 0.5, 0.0]
    d.GaussianRadius = 1.0
    d.ShaderPreset = "Sphere"
    d.ColorArrayName = ["POINTS", ""]
    d.AmbientColor = d.DiffuseColor = colour
    return d
