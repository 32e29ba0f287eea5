"""Renders one snapshot of a seixo output series to a PNG through ParaView:

    pvbatch render.py SERIES.xmf OUT.png [SNAPSHOT]

(scripts/render runs it headless). The balls are drawn as spheres of their
radius coloured by speed, the walls as translucent surfaces, the bonds as
lines and the cracks (the bonds broken so far) as points, red in tension and
blue in shear. SNAPSHOT is an index into the series, negative from the end
(default -1, the last). The blocks are picked by their names in the .xmf
(balls, walls, bonds, cracks) through ParaView's "XDMF Reader" (XdmfReader),
which keeps the names (each block a temporal collection of the .xmf) and
finds the .h5 beside an .xmf given by a bare file name. The Xdmf3 readers
do neither: "Xdmf3 Reader (Top Level Partition)", the one OpenDataFile
picks, makes every snapshot one dataset of unnamed pieces, and both Xdmf3
readers look for the .h5 of a bare "series.xmf" at "series.xmfseries.h5"."""
import os
import sys

from paraview import servermanager as sm
from paraview.simple import *  # noqa: F401,F403 (pvbatch's scripting interface)

PICK = """
from vtkmodules.vtkCommonDataModel import vtkCompositeDataSet
d = self.GetInputDataObject(0, 0)
for i in range(d.GetNumberOfBlocks()):
    name = d.GetMetaData(i).Get(vtkCompositeDataSet.NAME()) if d.HasMetaData(i) else ''
    if d.GetBlock(i) is not None and (name == '%s' or name.startswith('%s[')):
        self.GetOutputDataObject(0).ShallowCopy(d.GetBlock(i))
"""


def _named_block(reader, name):
    """The named block of the series' snapshot, as a dataset of its own."""
    f = ProgrammableFilter(Input=reader)
    f.OutputDataSetType = "vtkUnstructuredGrid"
    f.Script = PICK % (name, name)
    return f


def _count(source, t, cells=False):
    source.UpdatePipeline(t)
    info = source.GetDataInformation()
    return info.GetNumberOfCells() if cells else info.GetNumberOfPoints()


def main():
    if len(sys.argv) < 3:
        print("usage: pvbatch render.py SERIES.xmf OUT.png [SNAPSHOT]")
        sys.exit(2)
    xmf, png = sys.argv[1], os.path.abspath(sys.argv[2])  # the reader finds the .h5 by a bare name too
    which = int(sys.argv[3]) if len(sys.argv) > 3 else -1
    reader = XDMFReader(FileNames=[xmf])
    times = list(reader.TimestepValues) if reader.TimestepValues else [0.0]
    if not -len(times) <= which < len(times):
        print("render: the series has %d snapshots, no snapshot %d" % (len(times), which))
        sys.exit(1)
    t = times[which]
    view = CreateView("RenderView")
    view.ViewSize = [1024, 768]
    view.ViewTime = t
    view.UseColorPaletteForBackground = 0
    view.Background = [1, 1, 1]
    view.OrientationAxesVisibility = 1

    balls = _named_block(reader, "balls")
    glyph = Glyph(Input=balls, GlyphType="Sphere")
    glyph.ScaleArray = ["POINTS", "radius"]
    glyph.ScaleFactor = 2.0  # the sphere source has radius 0.5: scale by the diameter
    glyph.GlyphMode = "All Points"
    shown = Show(glyph, view)
    ColorBy(shown, ("POINTS", "velocity", "Magnitude"))
    shown.SetScalarBarVisibility(view, True)

    walls = _named_block(reader, "walls")
    w = Show(walls, view)
    w.Opacity = 0.25
    w.DiffuseColor = [0.5, 0.5, 0.5]

    bonds = _named_block(reader, "bonds")
    b = Show(bonds, view)
    b.DiffuseColor = [0.2, 0.2, 0.2]
    b.AmbientColor = [0.2, 0.2, 0.2]

    cracks = _named_block(reader, "cracks")
    c = Show(cracks, view)
    c.SetRepresentationType("Points")
    c.PointSize = 8
    c.RenderPointsAsSpheres = 1
    ColorBy(c, ("POINTS", "mode"))
    lut = GetColorTransferFunction("mode")
    lut.InterpretValuesAsCategories = 1
    lut.Annotations = ["1", "tension", "2", "shear"]
    lut.IndexedColors = [0.9, 0.1, 0.1, 0.1, 0.2, 0.9]

    n = {"balls": _count(balls, t), "walls": _count(walls, t, True), "bonds": _count(bonds, t, True),
         "cracks": _count(cracks, t)}
    text = Text(Text="%s  t = %.4g s" % (os.path.basename(xmf), t))
    label = Show(text, view)
    label.Color = [0, 0, 0]
    ResetCamera(view)
    camera = GetActiveCamera()
    camera.Elevation(-60)
    camera.Azimuth(30)
    ResetCamera(view)
    Render(view)
    SaveScreenshot(png, view, ImageResolution=[1024, 768])
    print("render: wrote %s (snapshot %d of %d, t = %g s): %d balls, %d wall cells, %d bonds, %d cracks"
          % (png, which % len(times) + 1, len(times), t, n["balls"], n["walls"], n["bonds"], n["cracks"]))


main()
