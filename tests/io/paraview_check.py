"""A real reader for seixo's output: ParaView opens a series through its
XDMF file, finds every snapshot, the balls with their fields, the contacts
and bonds as line cells, and renders the balls as spheres into a PNG.

    pvbatch paraview_check.py SERIES.xmf SNAPSHOTS BALLS RMIN RMAX OUT.png

Exits 0 when every check passes, 1 otherwise (with the reason)."""
import sys

from paraview import servermanager as sm
from paraview.simple import *  # noqa: F401,F403 (pvbatch's scripting interface)


def fail(why):
    print("paraview_check: FAILED: " + why)
    sys.exit(1)


def pieces(data):
    """The datasets of a reader's output, whichever XDMF reader made it."""
    out = []
    if data.IsA("vtkMultiBlockDataSet"):
        for i in range(data.GetNumberOfBlocks()):
            out += pieces(data.GetBlock(i))
    elif data.IsA("vtkMultiPieceDataSet"):
        for i in range(data.GetNumberOfPieces()):
            out += pieces(data.GetPiece(i))
    elif data is not None:
        out.append(data)
    return out


def main():
    xmf, snapshots, balls, rmin, rmax, png = sys.argv[1:7]
    snapshots, balls, rmin, rmax = int(snapshots), int(balls), float(rmin), float(rmax)
    reader = OpenDataFile(xmf)
    if reader is None:
        fail("ParaView found no reader for " + xmf)
    times = list(reader.TimestepValues)
    print("reader %s, %d time steps, last t = %g s" % (reader.GetXMLName(), len(times), times[-1]))
    if len(times) != snapshots:
        fail("%d time steps, %d expected" % (len(times), snapshots))
    reader.UpdatePipeline(times[-1])
    parts = pieces(sm.Fetch(reader))
    ball_parts = [p for p in parts if p.GetPointData().GetArray("radius") is not None]
    if len(ball_parts) != 1:
        fail("%d datasets carry a 'radius' point field, 1 expected" % len(ball_parts))
    b = ball_parts[0]
    print("balls: %d points, %d cells" % (b.GetNumberOfPoints(), b.GetNumberOfCells()))
    if b.GetNumberOfPoints() != balls or b.GetNumberOfCells() != balls:
        fail("%d points and %d cells, %d balls expected" % (b.GetNumberOfPoints(), b.GetNumberOfCells(), balls))
    lo, hi = b.GetPointData().GetArray("radius").GetRange()
    print("radius range [%g, %g] m" % (lo, hi))
    if abs(lo - rmin) > 1e-12 or abs(hi - rmax) > 1e-12:
        fail("radius range [%g, %g], [%g, %g] expected" % (lo, hi, rmin, rmax))
    for name in ("velocity", "spin", "force"):
        a = b.GetPointData().GetArray(name)
        if a is None or a.GetNumberOfComponents() != 3:
            fail("the balls have no 3-component '%s' field" % name)
    vlo, vhi = b.GetPointData().GetArray("velocity").GetRange(-1)
    print("velocity magnitude range [%g, %g] m/s" % (vlo, vhi))
    lines = [p for p in parts if p.GetCellData().GetArray("normal_force") is not None and p.GetNumberOfCells() > 0]
    if not lines:
        fail("no contacts or bonds as line cells with a 'normal_force' field")
    print("line datasets (contacts, bonds, wall contacts): %s cells" % [p.GetNumberOfCells() for p in lines])
    # the scene's mesh wall, a tetrahedron: four triangles (VTK cell type 5)
    meshes = [p for p in parts if p.GetNumberOfCells() > 0 and p.GetCellType(0) == 5]
    if len(meshes) != 1 or meshes[0].GetNumberOfCells() != 4 or meshes[0].GetNumberOfPoints() != 4:
        fail("no dataset of the mesh wall's 4 triangles on 4 points: %s" %
             [(p.GetNumberOfCells(), p.GetNumberOfPoints()) for p in meshes])
    print("mesh wall: %d triangles" % meshes[0].GetNumberOfCells())

    # the balls as spheres of their radius, coloured by speed: the dataset
    # with a 'radius' point field picked out of the snapshot
    balls_only = ProgrammableFilter(Input=reader)
    balls_only.OutputDataSetType = "vtkUnstructuredGrid"
    balls_only.Script = """
def visit(d):
    if d is None:
        return
    if d.IsA('vtkMultiBlockDataSet'):
        for i in range(d.GetNumberOfBlocks()): visit(d.GetBlock(i))
    elif d.IsA('vtkMultiPieceDataSet'):
        for i in range(d.GetNumberOfPieces()): visit(d.GetPiece(i))
    elif d.GetPointData().GetArray('radius') is not None:
        self.GetOutputDataObject(0).ShallowCopy(d)
visit(self.GetInputDataObject(0, 0))
"""
    view = CreateView("RenderView")
    view.ViewSize = [800, 600]
    view.OrientationAxesVisibility = 0
    glyph = Glyph(Input=balls_only, GlyphType="Sphere")
    glyph.ScaleArray = ["POINTS", "radius"]
    glyph.ScaleFactor = 2.0  # the sphere source has radius 0.5: scale by the diameter
    glyph.GlyphMode = "All Points"
    glyph.GlyphType.ThetaResolution = 16
    glyph.GlyphType.PhiResolution = 16
    shown = Show(glyph, view)
    ColorBy(shown, ("POINTS", "velocity", "Magnitude"))
    view.ViewTime = times[-1]
    ResetCamera(view)
    camera = GetActiveCamera()
    camera.Elevation(-60)
    camera.Azimuth(30)
    ResetCamera(view)
    Render(view)
    SaveScreenshot(png, view, ImageResolution=[800, 600])
    glyph.UpdatePipeline(times[-1])
    ntri = glyph.GetDataInformation().GetNumberOfCells()
    print("rendered %d sphere facets into %s" % (ntri, png))
    if ntri < balls * 100:
        fail("the glyphs made %d facets, too few for %d spheres" % (ntri, balls))
    print("paraview_check: OK")


main()
