"""surge report DIR: one self-contained page, looked at in headless Chromium.

The small run of export_runs.py is simulated, surfaced, rasterised, made a video and reported. The page must hold
its plots as inline SVG (one each of density error, energy, iterations, particles and wall time, one a body and a
collider), the contact sheet as base64 PNG equal to the file, and the video by its relative path. Chromium
(Debian chromium) screenshots the page's top, where the plots are: that band must not be blank (2.5% of its
pixels not white) and must show the plot lines (thousands of pixels of the first series' colour, hundreds of the
second's). A folder without stats.csv must give one line, exit 2 and no page. Exit 77 (ctest's skip) where
chromium, or python3-vtk9 (its PNG reader), is missing.

Usage: report_test.py SURGE_BINARY WORK_FOLDER
"""
import base64
import os
import re
import shutil
import subprocess
import sys

from export_runs import SCENE, Checks, make_run, require, surge

np, vtk, numpy_support = require("numpy", "vtk", "vtk.util.numpy_support")
vtk_to_numpy = numpy_support.vtk_to_numpy

check = Checks()
WIDTH, HEIGHT, PLOTS_TOP = 1200, 1000, 200  # the window; the plots start below the title and the summary


def screenshot(chromium, page, png, profile):
    subprocess.run([chromium, "--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
                    "--disable-component-update", "--disable-sync", "--no-first-run", f"--user-data-dir={profile}",
                    f"--screenshot={png}", f"--window-size={WIDTH},{HEIGHT}", "file://" + page],
                   capture_output=True, text=True, timeout=120)
    reader = vtk.vtkPNGReader()
    reader.SetFileName(png)
    reader.Update()
    image = reader.GetOutput()
    width, height, _ = image.GetDimensions()
    pixels = vtk_to_numpy(image.GetPointData().GetScalars()).reshape(height, width, -1)[::-1, :, :3]
    return pixels.astype(int)  # rows from the top, RGB


def main():
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    if not chromium:
        print("SKIP: chromium is not installed (Debian chromium; scripts/setup.sh)")
        return 77
    binary, work = sys.argv[1], os.path.join(sys.argv[2], "report_test")
    run = make_run(binary, work)
    result = surge(binary, "report", os.path.join(run, "particles"))
    check(result.returncode == 2 and "scene.json" in result.stderr and result.stderr.count("\n") == 1,
          f"a folder that is not a run: exit {result.returncode}, {result.stderr!r}")
    os.rename(os.path.join(run, "stats.csv"), os.path.join(work, "stats.csv"))
    result = surge(binary, "report", run)
    check(result.returncode == 2 and "stats.csv" in result.stderr and result.stderr.count("\n") == 1,
          f"a run without stats.csv: exit {result.returncode}, {result.stderr!r}")
    check(not os.path.exists(os.path.join(run, "report.html")), "a run without stats.csv got a report")
    os.rename(os.path.join(work, "stats.csv"), os.path.join(run, "stats.csv"))
    for step in (["render", run, "--renderer", "gl"], ["video", run], ["report", run]):
        result = surge(binary, *step)
        if result.returncode != 0:
            print(f"surge {step[0]} failed: {result.stderr}")
            return 1

    page = os.path.join(run, "report.html")
    with open(page) as f:
        html = f.read()
    svgs = re.findall(r"<svg.*?</svg>", html, re.S)
    check(len(svgs) == 5 + 1 + 2, f"{len(svgs)} plots, not 5 of stats.csv, 1 a body and 1 each of 2 colliders")
    for svg in svgs:
        lines = re.findall(r'<polyline [^>]*points="([^"]*)"', svg)
        check(lines and all(len(points.split()) == SCENE["output"]["frames"] + 1 or
                            len(points.split()) == SCENE["output"]["frames"] for points in lines),
              f"a plot's lines do not have a point a frame: {[len(p.split()) for p in lines]}")
    sources = re.findall(r'src="([^"]*)"', html)
    images = [s for s in sources if s.startswith("data:image/png;base64,")]
    check(len(images) == 1, f"{len(images)} embedded images")
    with open(os.path.join(run, SCENE["name"] + "_contact_sheet.png"), "rb") as f:
        check(images and base64.b64decode(images[0].split(",", 1)[1]) == f.read(), "the contact sheet embedded")
    check(sources.count(SCENE["name"] + ".mp4") == 1, f"the video by its relative path: {sources[:1]}")
    check(all(s.startswith("data:") or s == SCENE["name"] + ".mp4" for s in sources), "other files named")

    pixels = screenshot(chromium, page, os.path.join(work, "report.png"), os.path.join(work, "chromium"))
    band = pixels[PLOTS_TOP:]
    not_white = np.any(band < 245, axis=2).mean()
    blue = (np.abs(band - [31, 119, 180]).sum(axis=2) < 60).sum()
    red = (np.abs(band - [214, 39, 40]).sum(axis=2) < 60).sum()
    print(f"plots band: {not_white:.1%} not white, {blue} pixels of the first line colour, {red} of the second")
    check(not_white > 0.025, f"the plots band is {not_white:.1%} not white")
    check(blue > 2000 and red > 500, f"plot lines: {blue} blue and {red} red pixels")
    return check.status()


if __name__ == "__main__":
    sys.exit(main())
