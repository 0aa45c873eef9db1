"""Opens a run's XDMF sidecar with ParaView's XDMF reader and prints what it sees.

    apt-get install paraview python3-paraview
    pvbatch --force-offscreen-rendering scripts/check_xdmf_paraview.py run.xmf [FRAME]

Prints the number of time steps, the grains and point arrays of one frame, and the first
grain's position, to compare with `h5dump -d /particles/grains/position/value -s F,0,0 -c 1,1,3`.
"""
import sys

from paraview import servermanager
from paraview.simple import XDMFReader

path = sys.argv[1]
frame = int(sys.argv[2]) if len(sys.argv) > 2 else 0
reader = XDMFReader(FileNames=[path])
reader.UpdatePipelineInformation()
times = list(reader.TimestepValues or [0])
reader.UpdatePipeline(times[frame])
grid = servermanager.Fetch(reader)
data = grid.GetPointData()
print(f"{path}: {len(times)} time steps; frame {frame} (time {times[frame]}): "
      f"{grid.GetNumberOfPoints()} grains, arrays "
      f"{[data.GetArrayName(i) for i in range(data.GetNumberOfArrays())]}")
print("first grain at", grid.GetPoint(0))
