# SPDX-License-Identifier: BSD-3-Clause
"""VTK's figures of a welded PLY mesh, for tests/tools/measure.sh: the area by
vtkMassProperties, the region count of vtkPolyDataConnectivityFilter (all regions) and the
triangle count of its largest region, as "area regions largest_triangles" on one line. Exits 77
when VTK cannot be imported (the test then skips that part)."""
import sys

try:
    import vtk
except ImportError:
    sys.exit(77)

reader = vtk.vtkPLYReader()
reader.SetFileName(sys.argv[1])
reader.Update()
mass = vtk.vtkMassProperties()
mass.SetInputConnection(reader.GetOutputPort())
mass.Update()
regions = vtk.vtkPolyDataConnectivityFilter()
regions.SetInputConnection(reader.GetOutputPort())
regions.SetExtractionModeToAllRegions()
regions.Update()
largest = vtk.vtkPolyDataConnectivityFilter()
largest.SetInputConnection(reader.GetOutputPort())
largest.SetExtractionModeToLargestRegion()
largest.Update()
print(mass.GetSurfaceArea(), regions.GetNumberOfExtractedRegions(),
      largest.GetOutput().GetNumberOfCells())
