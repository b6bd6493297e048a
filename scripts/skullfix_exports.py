#!/usr/bin/python3
"""Exports of a SkullFix defective skull as other programs make them, with VTK's own filters.

Usage: scripts/skullfix_exports.py CASE_NRRD OUTDIR

Reads the mask (gzip-encoded NRRD, as SkullFix ships it) without the project's reader, places
it by the header's space directions and origin (LPS, oblique directions included), and writes
binary STLs:
  open          flying edges at 0.5 on the mask as it is: open where the bone meets the
                volume's border, small pieces kept (what most exporters give)
  sinc05        open, then a windowed-sinc smoothing (pass band 0.05, 15 iterations, as
                Slicer's model smoothing)
  sinc05_dec20  the smoothed surface quadric-decimated to 20 % of its triangles
  gauss1        the mask blurred (sigma one voxel) before the iso-surface at 0.5 (as a
                segmentation smoothed before export)
  cluster250    open, re-meshed by vertex clustering on a 250^3 grid (holes, non-manifold
                edges and folded triangles, as clustering decimation leaves them)
  slicer05      as 3D Slicer's Segment Editor makes a model of a segment: the mask as a binary
                labelmap padded by a voxel (closed), discrete flying edges, a windowed-sinc
                smoothing of 20 iterations with pass band 10^(-4 x factor), factor 0.5 (its
                default)
  slicer10      the same with smoothing factor 1 (the strongest of the common settings)
Needs Debian's python3-vtk9 (scripts/skullfix-exports installs it).
"""
import gzip
import re
import sys

import vtk


def read_nrrd(path):
    raw = open(path, "rb").read()
    cut = raw.index(b"\n\n")
    header = raw[:cut].decode("latin1")
    field = lambda name: re.search(r"^" + name + r":\s*(.*)$", header, re.M).group(1).strip()
    if field("encoding") not in ("gzip", "gz"):
        sys.exit(f"{path}: only gzip-encoded NRRD is read here, not {field('encoding')}")
    kind = field("type")
    types = {"int": "Int", "int32": "Int", "short": "Short", "int16": "Short",
             "unsigned char": "UnsignedChar", "uchar": "UnsignedChar", "uint8": "UnsignedChar"}
    if kind not in types:
        sys.exit(f"{path}: voxel type {kind} not handled here")
    data = gzip.decompress(raw[cut + 2:])
    sizes = [int(s) for s in field("sizes").split()]
    columns = [[float(x) for x in v.split(",")]
               for v in re.findall(r"\(([^)]*)\)", field("space directions"))]
    origin = [float(x) for x in re.search(r"\(([^)]*)\)", field("space origin")).group(1).split(",")]
    image = vtk.vtkImageImport()
    image.CopyImportVoidPointer(data, len(data))
    getattr(image, "SetDataScalarTypeTo" + types[kind])()
    image.SetNumberOfScalarComponents(1)
    image.SetWholeExtent(0, sizes[0] - 1, 0, sizes[1] - 1, 0, sizes[2] - 1)
    image.SetDataExtentToWholeExtent()
    image.Update()
    as_float = vtk.vtkImageCast()
    as_float.SetInputConnection(image.GetOutputPort())
    as_float.SetOutputScalarTypeToFloat()
    as_float.Update()
    # Index to LPS millimetres: origin + directions (columns) times the index.
    matrix = vtk.vtkMatrix4x4()
    for i in range(3):
        for j in range(3):
            matrix.SetElement(i, j, columns[j][i])
        matrix.SetElement(i, 3, origin[i])
    to_lps = vtk.vtkTransform()
    to_lps.SetMatrix(matrix)
    return as_float.GetOutput(), to_lps


def iso_surface(image, level):
    f = vtk.vtkFlyingEdges3D()
    f.SetInputData(image)
    f.SetValue(0, level)
    f.ComputeNormalsOff()
    f.Update()
    return f.GetOutput()


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    path, out = sys.argv[1], sys.argv[2]
    name = re.sub(r"_defective_skull\.nrrd$", "", path.split("/")[-1])
    image, to_lps = read_nrrd(path)

    def write(surface, variant):
        placed = vtk.vtkTransformPolyDataFilter()
        placed.SetInputData(surface)
        placed.SetTransform(to_lps)
        placed.Update()
        w = vtk.vtkSTLWriter()
        w.SetFileName(f"{out}/{name}_{variant}.stl")
        w.SetFileTypeToBinary()
        w.SetInputData(placed.GetOutput())
        w.Write()
        print(f"{name}_{variant}.stl: {surface.GetNumberOfPolys()} triangles")

    base = iso_surface(image, 0.5)
    write(base, "open")
    smooth = vtk.vtkWindowedSincPolyDataFilter()
    smooth.SetInputData(base)
    smooth.SetNumberOfIterations(15)
    smooth.SetPassBand(0.05)
    smooth.NormalizeCoordinatesOn()
    smooth.BoundarySmoothingOff()
    smooth.FeatureEdgeSmoothingOff()
    smooth.NonManifoldSmoothingOn()
    smooth.Update()
    write(smooth.GetOutput(), "sinc05")
    fewer = vtk.vtkQuadricDecimation()
    fewer.SetInputData(smooth.GetOutput())
    fewer.SetTargetReduction(0.8)
    fewer.Update()
    write(fewer.GetOutput(), "sinc05_dec20")
    blur = vtk.vtkImageGaussianSmooth()
    blur.SetInputData(image)
    blur.SetStandardDeviations(1.0, 1.0, 1.0)
    blur.Update()
    write(iso_surface(blur.GetOutput(), 0.5), "gauss1")
    cluster = vtk.vtkQuadricClustering()
    cluster.SetInputData(base)
    cluster.SetNumberOfDivisions(250, 250, 250)
    cluster.Update()
    triangles = vtk.vtkTriangleFilter()
    triangles.SetInputData(cluster.GetOutput())
    triangles.Update()
    write(triangles.GetOutput(), "cluster250")
    # 3D Slicer's closed surface of a segment: the labelmap padded so that the surface closes
    # (the padded image keeps index coordinates: its extent starts at -1), its boundary by
    # discrete flying edges, smoothed as Slicer's "Smoothing factor" does.
    label = vtk.vtkImageThreshold()
    label.SetInputData(image)
    label.ThresholdByUpper(0.5)
    label.SetInValue(1)
    label.SetOutValue(0)
    label.SetOutputScalarTypeToUnsignedChar()
    label.Update()
    extent = label.GetOutput().GetExtent()
    pad = vtk.vtkImageConstantPad()
    pad.SetInputData(label.GetOutput())
    pad.SetOutputWholeExtent(extent[0] - 1, extent[1] + 1, extent[2] - 1, extent[3] + 1,
                             extent[4] - 1, extent[5] + 1)
    pad.SetConstant(0)
    pad.Update()
    boundary = vtk.vtkDiscreteFlyingEdges3D()
    boundary.SetInputData(pad.GetOutput())
    boundary.SetValue(0, 1)
    boundary.ComputeNormalsOff()
    boundary.ComputeGradientsOff()
    boundary.Update()
    for factor, variant in ((0.5, "slicer05"), (1.0, "slicer10")):
        slicer = vtk.vtkWindowedSincPolyDataFilter()
        slicer.SetInputData(boundary.GetOutput())
        slicer.SetNumberOfIterations(20)
        slicer.SetPassBand(10.0 ** (-4.0 * factor))
        slicer.NormalizeCoordinatesOn()
        slicer.BoundarySmoothingOff()
        slicer.FeatureEdgeSmoothingOff()
        slicer.NonManifoldSmoothingOn()
        slicer.Update()
        write(slicer.GetOutput(), variant)


if __name__ == "__main__":
    main()
