"""ParaView's "XDMF Reader" shows seixo's blocks by name, whatever the
working directory and however the .xmf is named (bare, relative):

    pvpython pv_names.py SERIES.xmf SNAPSHOTS NAME...

At the last snapshot the reader's top-level blocks must be exactly the
NAMEs given, in order, none of them empty; at the first snapshot the same
names in the same order (a block may be empty then: no cracks yet), since
each block is a temporal collection of its own. Prints "pv_names: OK" when
every check passes. Also prints what OpenDataFile's default reader makes
of the file (for the record: no names)."""
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
    for t, last in ((times[0], False), (times[-1], True)):
        reader.UpdatePipeline(t)
        data = sm.Fetch(reader)
        found = []
        for i in range(data.GetNumberOfBlocks()):
            name = data.GetMetaData(i).Get(vtkCompositeDataSet.NAME()) if data.HasMetaData(i) else None
            block = data.GetBlock(i)
            size = block.GetNumberOfPoints() if block is not None else 0
            print("  t = %g s, block %d: %s, %d points" % (t, i, name, size))
            if last and size == 0:
                fail("block %s is empty at the last snapshot" % name)
            found.append(name)
        if found != names:
            fail("blocks %s at t = %g s, %s expected" % (found, t, names))
    default = OpenDataFile(os.path.abspath(xmf))
    default.UpdatePipeline(times[-1])
    top = sm.Fetch(default)
    print("OpenDataFile's default reader %s gives a %s of %d blocks" %
          (default.GetXMLName(), top.GetClassName(), top.GetNumberOfBlocks()))
    print("pv_names: OK")


main()
