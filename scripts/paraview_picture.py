"""The ParaView picture of docs/exchange-formats.md: a `surge export --format vtk` folder's surface (grey, half
see-through) and particles coloured by speed at one frame, rendered headless.

    xvfb-run -a -s "-screen 0 1280x1024x24" pvbatch scripts/paraview_picture.py out/dam_break/export shot.png [FRAME]

Debian: paraview, python3-paraview, and xvfb (Debian's ParaView renders through X, so pvbatch needs a display even
with --force-offscreen-rendering). Not in scripts/setup.sh: 440 MB for one picture, no test needs it.
"""
from paraview.simple import *
import sys
export = sys.argv[1]
out = sys.argv[2]
surface = PVDReader(FileName=export + "/surface.pvd")
particles = PVDReader(FileName=export + "/particles.pvd")
scene = GetAnimationScene()
scene.UpdateAnimationUsingDataTimeSteps()
view = CreateView("RenderView")
view.ViewSize = [960, 540]
view.Background = [1, 1, 1]
view.UseColorPaletteForBackground = 0
view.OrientationAxesVisibility = 0
time = surface.TimestepValues[int(sys.argv[3]) if len(sys.argv) > 3 else 30]
view.ViewTime = time
sd = Show(surface, view)
sd.Representation = "Surface"
sd.DiffuseColor = [0.75, 0.8, 0.85]
sd.Opacity = 0.35
pd = Show(particles, view)
pd.Representation = "Points"
pd.PointSize = 2
ColorBy(pd, ("POINTS", "velocity", "Magnitude"))
lut = GetColorTransferFunction("velocity")
lut.ApplyPreset("Turbo", True)
lut.RescaleTransferFunction(0.0, 3.0)
bar = GetScalarBar(lut, view)
bar.Title = "speed (m/s)"
bar.ComponentTitle = ""
bar.TitleColor = [0, 0, 0]
bar.LabelColor = [0, 0, 0]
bar.Visibility = 1
Render(view)  # the first render frames the data; the camera is set after it
view.CameraPosition = [1.6, 1.6, 3.6]
view.CameraFocalPoint = [1.6, 0.25, 0.3]
view.CameraViewUp = [0, 1, 0]
view.ResetCamera()
cam = view.GetActiveCamera()
cam.Elevation(25)
cam.Azimuth(-25)
cam.Dolly(1.1)
Render(view)
SaveScreenshot(out, view, ImageResolution=[960, 540])
print("saved", out, "at", time, "s")
