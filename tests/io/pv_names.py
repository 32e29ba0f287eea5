"""ParaView's "XDMF Reader" shows seixo's blocks by name, whatever the
working directory and however the .xmf is named (bare, relative):

    pvpython pv_names.py SERIES.xmf SNAPSHOTS NAME...

At the last snapshot the reader's top-level blocks must be exactly the
NAMEs given, in order (each possibly suffixed "[k]", the reader's mark of a
name that repeats in the file), none of them empty. Prints "pv_names: OK"
when every check passes. Also prints what OpenDataFile's default reader
makes of the file (for the record: no names)."""
import os
import sys

from paraview import servermanager as sm
from paraview.simple import OpenDataFile, XDMFReader
from vtkmodules.vtkCommonDataModel import vtkCompositeDataSet


def fail(why):
    print("pv_names: FAILED: " + why)
    sys.exit(1)


def main():
    xmf, snapshots, names = sys.argv[1], int(sys.argv[2]), sys.argv[3:]
    reader = XDMFReader(FileNames=[xmf])
    times = list(reader.TimestepValues or [])
    print("cwd %s, file %s: %d time steps" % (os.getcwd(), xmf, len(times)))
    if len(times) != snapshots:
        fail("%d time steps, %d expected" % (len(times), snapshots))
    reader.UpdatePipeline(times[-1])
    data = sm.Fetch(reader)
    found = []
    for i in range(data.GetNumberOfBlocks()):
        name = data.GetMetaData(i).Get(vtkCompositeDataSet.NAME()) if data.HasMetaData(i) else None
        block = data.GetBlock(i)
        size = block.GetNumberOfPoints() if block is not None else 0
        print("  block %d: %s, %d points" % (i, name, size))
        if not name:
            fail("block %d has no name" % i)
        if size == 0:
            fail("block %s is empty" % name)
        found.append(name.split("[")[0])
    if found != names:
        fail("blocks %s, %s expected" % (found, names))
    default = OpenDataFile(os.path.abspath(xmf))
    default.UpdatePipeline(times[-1])
    top = sm.Fetch(default)
    print("OpenDataFile's default reader %s gives a %s of %d blocks" %
          (default.GetXMLName(), top.GetClassName(), top.GetNumberOfBlocks()))
    print("pv_names: OK")


main()
