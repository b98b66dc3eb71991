"""Run by ParaView's pvpython (offscreen), not by python3: render one frame's damage in 3D.

    pvpython --force-offscreen-rendering pvpython_damage.py FRAME.vtu OUT.png TITLE THRESHOLD

The body as faint points (its shape), the nodes with damage > THRESHOLD as spheres coloured by
damage (0…1), an oblique camera, a white background, the title on top. Called by
postprocess/render3d.py, which falls back to matplotlib when this fails.
"""
import sys

from paraview.simple import (ColorBy, GetActiveCamera, GetColorTransferFunction, GetScalarBar,  # noqa: E402
                             SaveScreenshot, Show, Text, Threshold, XMLUnstructuredGridReader,
                             CreateView)

frame, out, title, threshold = sys.argv[1], sys.argv[2], sys.argv[3], float(sys.argv[4])
SIZE = [1200, 900]

view = CreateView("RenderView")
view.ViewSize = SIZE
view.Background = [1.0, 1.0, 1.0]
try:  # ParaView ≥ 5.10 keeps the background of the colour palette unless told otherwise
    view.UseColorPaletteForBackground = 0
except AttributeError:
    pass
view.OrientationAxesVisibility = 1

reader = XMLUnstructuredGridReader(FileName=[frame])
body = Show(reader, view)
body.SetRepresentationType("Points")
body.ColorArrayName = ["POINTS", ""]  # one plain colour
body.AmbientColor = body.DiffuseColor = [0.55, 0.55, 0.55]
body.Opacity = 0.12
body.PointSize = 2.0

damaged = Threshold(Input=reader)
damaged.Scalars = ["POINTS", "damage"]
try:  # ParaView ≥ 5.10
    damaged.LowerThreshold, damaged.UpperThreshold = threshold, 1.0
    damaged.ThresholdMethod = "Between"
except AttributeError:
    damaged.ThresholdRange = [threshold, 1.0]
shown = Show(damaged, view)
shown.SetRepresentationType("Points")
shown.RenderPointsAsSpheres = 1
shown.PointSize = 5.0
ColorBy(shown, ("POINTS", "damage"))
lut = GetColorTransferFunction("damage")
lut.ApplyPreset("Inferno (matplotlib)", True)
lut.InvertTransferFunction()
lut.RescaleTransferFunction(0.0, 1.0)
lut.AutomaticRescaleRangeMode = "Never"
shown.SetScalarBarVisibility(view, True)
bar = GetScalarBar(lut, view)
bar.Title, bar.ComponentTitle = "damage [-]", ""
bar.AutomaticLabelFormat = 0
bar.LabelFormat = bar.RangeLabelFormat = "%-#.1f"
bar.TitleColor = bar.LabelColor = [0.0, 0.0, 0.0]

label = Text(Text=title)
text = Show(label, view)
text.Color = [0.0, 0.0, 0.0]
text.WindowLocation = "Upper Center"
text.FontSize = 18

view.ResetCamera()
camera = GetActiveCamera()
camera.Elevation(35.0)
camera.Azimuth(-30.0)
view.ResetCamera()
SaveScreenshot(out, view, ImageResolution=SIZE)
