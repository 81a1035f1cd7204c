#!/usr/bin/env python3
"""The picture of surface_bezier.vtu as ParaView draws it (docs/paraview.md), made with
VTK's own rendering (offscreen; without a display run it under xvfb-run, as
scripts/make_pictures.sh does):

    PYTHONPATH=build/python xvfb-run -a python3 scripts/bezier_picture.py OUTDIR PICTURE.png

Parameterizes the Comoros sea (tests/data/seas/comoros.txt: three islands as
holes, a multi-patch map) with tspline.parameterize, writes the files of
`tspline param` into OUTDIR (surface.vtu with one flat quad per cell), and
draws three views coloured by the mean ratio Jacobian J_r: the whole map from
surface_bezier.vtu, and one coast up close from surface.vtu (flat facets) and
from surface_bezier.vtu (VTK's rational Bezier cells tessellated with a
nonlinear subdivision level of 4, as ParaView's "Nonlinear Subdivision Level"
does). Cell outlines are drawn by evaluating each cell's edges with VTK."""
import pathlib
import sys

import vtk

import tspline

out = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "out/comoros_py")
picture = sys.argv[2] if len(sys.argv) > 2 else "docs/images/comoros_bezier.png"

m = tspline.parameterize("tests/data/seas/comoros.txt", samples=1)
m.save(out)
print(f"{m.patches} patches, {m.cells} cells, certified valid: {m.certified_valid}")


def read(name):
    reader = vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(str(out / name))
    reader.Update()
    return reader.GetOutput()


def viridis():
    lut = vtk.vtkColorTransferFunction()
    for t, rgb in [(0.0, (0.267, 0.005, 0.329)), (0.25, (0.229, 0.322, 0.546)), (0.5, (0.128, 0.567, 0.551)),
                   (0.75, (0.369, 0.789, 0.383)), (1.0, (0.993, 0.906, 0.144))]:
        lut.AddRGBPoint(t, *rgb)
    return lut


def surface_actor(grid, subdivision):
    surface = vtk.vtkDataSetSurfaceFilter()
    surface.SetInputData(grid)
    surface.SetNonlinearSubdivisionLevel(subdivision)
    mapper = vtk.vtkPolyDataMapper()
    mapper.SetInputConnection(surface.GetOutputPort())
    mapper.SetScalarModeToUsePointFieldData()
    mapper.SelectColorArray("mean_ratio_jacobian")
    mapper.SetLookupTable(viridis())
    mapper.SetScalarRange(0.0, 1.0)
    mapper.InterpolateScalarsBeforeMappingOn()
    actor = vtk.vtkActor()
    actor.SetMapper(mapper)
    return actor


def outline_actor(grid, samples, width):
    """Every cell's border as VTK evaluates it (samples points per edge)."""
    points, lines = vtk.vtkPoints(), vtk.vtkCellArray()
    cell = vtk.vtkGenericCell()
    weights = [0.0] * 16
    border = [(t, 0.0) for t in range(samples)] + [(samples, t) for t in range(samples)] + \
             [(samples - t, samples) for t in range(samples)] + [(0.0, samples - t) for t in range(samples + 1)]
    for c in range(grid.GetNumberOfCells()):
        grid.GetCell(c, cell)
        ids = []
        for s, t in border:
            x = [0.0, 0.0, 0.0]
            cell.EvaluateLocation(vtk.reference(0), [s / samples, t / samples, 0.0], x, weights)
            ids.append(points.InsertNextPoint(x[0], x[1], 1e-3))
        lines.InsertNextCell(len(ids), ids)
    poly = vtk.vtkPolyData()
    poly.SetPoints(points)
    poly.SetLines(lines)
    mapper = vtk.vtkPolyDataMapper()
    mapper.SetInputData(poly)
    actor = vtk.vtkActor()
    actor.SetMapper(mapper)
    actor.GetProperty().SetColor(0.1, 0.1, 0.1)
    actor.GetProperty().SetLineWidth(width)
    return actor


def label(text):
    t = vtk.vtkTextActor()
    t.SetInput(text)
    t.GetTextProperty().SetFontSize(18)
    t.GetTextProperty().SetColor(0, 0, 0)
    t.GetTextProperty().SetBackgroundColor(1, 1, 1)
    t.GetTextProperty().SetBackgroundOpacity(0.85)
    t.SetPosition(10, 570)
    return t


def colour_bar():
    bar = vtk.vtkScalarBarActor()
    bar.SetLookupTable(viridis())
    bar.SetTitle("J_r")
    bar.UnconstrainedFontSizeOn()
    bar.GetTitleTextProperty().SetFontSize(18)
    bar.GetLabelTextProperty().SetFontSize(14)
    bar.SetNumberOfLabels(5)
    bar.SetPosition(0.88, 0.1)
    bar.SetWidth(0.09)
    bar.SetHeight(0.75)
    for p in (bar.GetTitleTextProperty(), bar.GetLabelTextProperty()):
        p.SetColor(0, 0, 0)
    return bar


bezier, flat = read("surface_bezier.vtu"), read("surface.vtu")
window = vtk.vtkRenderWindow()
window.SetOffScreenRendering(1)
window.SetSize(1800, 600)
# The zoomed region (km, the file's units).
zoom_centre, zoom_height = (-52.0, -1.0), 16.0  # the south cape of Grande Comore
views = [((0.0, 1 / 3), [surface_actor(bezier, 4), outline_actor(bezier, 8, 1.0)], None,
          "surface_bezier.vtu: the whole map, J_r"),
         ((1 / 3, 2 / 3), [surface_actor(flat, 0), outline_actor(flat, 1, 1.5)], zoom_centre,
          "surface.vtu, --samples 1: flat facets"),
         ((2 / 3, 1.0), [surface_actor(bezier, 4), outline_actor(bezier, 16, 1.5)], zoom_centre,
          "surface_bezier.vtu, nonlinear subdivision 4")]
for (x0, x1), actors, centre, text in views:
    r = vtk.vtkRenderer()
    r.SetViewport(x0, 0.0, x1, 1.0)
    r.SetBackground(1, 1, 1)
    for a in actors:
        r.AddActor(a)
    r.AddActor2D(label(text))
    if centre is None:
        r.AddActor2D(colour_bar())
    window.AddRenderer(r)
    r.ResetCamera()
    camera = r.GetActiveCamera()
    camera.ParallelProjectionOn()
    if centre:
        camera.SetFocalPoint(centre[0], centre[1], 0.0)
        camera.SetPosition(centre[0], centre[1], 100.0)
        camera.SetParallelScale(zoom_height / 2)
    else:
        camera.SetFocalPoint(*[a + b for a, b in zip(camera.GetFocalPoint(), (12.0, 0.0, 0.0))])
        camera.SetPosition(*[a + b for a, b in zip(camera.GetPosition(), (12.0, 0.0, 0.0))])
    r.ResetCameraClippingRange()
window.Render()
shot = vtk.vtkWindowToImageFilter()
shot.SetInput(window)
shot.Update()
writer = vtk.vtkPNGWriter()
writer.SetFileName(picture)
writer.SetInputConnection(shot.GetOutputPort())
writer.Write()
print("wrote", picture)
