#!/usr/bin/env python3
"""End to end: the viewer's pictures are right, pixel by pixel (with tolerance).

usage: viewer_pixels.py EXE SCENES OUT headless|window|mouse

- headless: `view --screenshot` renders without any display (EGL), deterministically, after the scripted
  probe pressed a block (viewer_block.toml);
- window:   the viewer in a real window under Xvfb, its scripted probe pressing the block in real time with
  the 1 kHz haptic loop running, the window's last frame saved;
- mouse:    the viewer under Xvfb on the default scene (the seed's beam) driven by a real pointer (xdotool):
  the cursor brings the probe down onto the beam, the left button grabs, the cursor lifts the beam; the
  grabbed points must come up; the S key saves a screenshot.

Each picture is checked against the camera the viewer reports (--info), projected here independently: the
probe's pixels have the probe's colour, the object's points land on object-coloured pixels, the background
is background away from the object, the picture is not blank and the panels are drawn."""
import glob
import json
import os
import shutil
import subprocess
import sys
import time

import numpy as np
from PIL import Image

exe, scenes, out, mode = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4]
os.makedirs(out, exist_ok=True)
BACKGROUND = np.array([0.13, 0.14, 0.17]) * 255
SIZE = (1024, 640)


def project(info, points):
    """Window pixels (x right, y down) of scene points, with the camera the viewer reports."""
    cam, (vx, vy, vw, vh) = info["camera"], info["viewport"]
    eye, target, up = (np.array(cam[k], float) for k in ("eye", "target", "up"))
    f = target - eye
    f /= np.linalg.norm(f)
    r = np.cross(f, up)
    r /= np.linalg.norm(r)
    u = np.cross(r, f)
    p = np.atleast_2d(points) - eye
    x, y, depth = p @ r, p @ u, p @ f
    t = np.tan(0.5 * cam["fov_y"])
    px = vx + 0.5 * vw * (1 + x / (depth * t * vw / vh))
    py = vy + 0.5 * vh * (1 - y / (depth * t))
    return np.stack([px, py], axis=1), depth, 0.5 * vh / (t * depth)  # pixels, depth, pixels per metre


def colour_distance(img, px, colour):
    x, y = int(round(px[0])), int(round(px[1]))
    return np.linalg.norm(img[y, x, :3].astype(float) - np.asarray(colour, float))


def check_picture(png, info_path, expect_contact):
    img = np.asarray(Image.open(png).convert("RGB")).astype(float)
    info = json.load(open(info_path))
    h, w = img.shape[:2]
    assert (w, h) == (info["image"]["width"], info["image"]["height"]), (w, h)
    vx, vy, vw, vh = info["viewport"]
    view = img[int(vy):int(vy + vh), int(vx):int(vx + vw)]
    # not blank: much of the view is not background, and in many colours
    not_bg = np.linalg.norm(view - BACKGROUND, axis=2) > 30
    assert 0.03 < not_bg.mean() < 0.9, f"{png}: {not_bg.mean():.3f} of the view is drawn"
    assert len(np.unique((view[not_bg] // 16).astype(int), axis=0)) > 20, f"{png}: too few colours"
    # the panels: the column left of the view is drawn (ImGui's dark-blue window with text)
    panel = img[:, : int(vx)]
    assert panel.std() > 10, f"{png}: the panel column is empty"

    # the probe: its centre pixel, and most of a disc around it, in the probe's colour (shaded)
    probe = np.array(info["probe"]["position"], float)
    (pc,), depth, ppm = project(info, probe)
    r_px = info["probe"]["radius"] * ppm[0]
    assert r_px > 4, f"{png}: the probe is only {r_px:.1f} px"
    colour = np.array(info["probe"]["colour"]) * 255
    hue = colour / colour.sum()
    ys, xs = np.mgrid[-int(r_px):int(r_px) + 1, -int(r_px):int(r_px) + 1]
    inside = xs**2 + ys**2 <= (0.6 * r_px) ** 2
    pixels = img[(ys[inside] + int(round(pc[1]))).clip(0, h - 1), (xs[inside] + int(round(pc[0]))).clip(0, w - 1)]
    chroma = pixels / np.maximum(pixels.sum(axis=1, keepdims=True), 1)
    probe_like = np.linalg.norm(chroma - hue, axis=1) < 0.08
    assert probe_like.mean() > 0.5, f"{png}: only {probe_like.mean():.2f} of the probe's disc at {pc} has its colour"

    # the object: its points land on drawn pixels that are not the probe's; background well outside it
    pts = np.array(info["sample_points"], float)
    pix, _, _ = project(info, pts)
    hits = 0
    considered = 0
    for p in pix:
        if np.linalg.norm(p - pc) < 1.3 * r_px:
            continue  # may be behind the probe
        considered += 1
        # the pixel or one within 2 px of it (a point on a box's edge lies on the surface's outline)
        x0, y0 = int(round(p[0])), int(round(p[1]))
        window = img[max(y0 - 2, 0):y0 + 3, max(x0 - 2, 0):x0 + 3].reshape(-1, 3)
        chroma = window / np.maximum(window.sum(axis=1, keepdims=True), 1)
        # the background is one flat colour; even a sphere's dark rim differs from it
        if np.any((np.linalg.norm(window - BACKGROUND, axis=1) > 8) & (np.linalg.norm(chroma - hue, axis=1) > 0.05)):
            hits += 1
    assert considered > 20 and hits / considered > 0.95, f"{png}: {hits} of {considered} object points on object pixels"
    # the surface (the default for a box): drawn, and its vertices land on object pixels too; a smooth
    # surface, unlike a heap of balls, has few pixels as dark as a sphere's rim inside its outline
    if info["surface"]["drawn"]:
        assert info["surface"]["triangles"] > 100, info["surface"]
        vpix, _, _ = project(info, np.array(info["surface"]["sample_vertices"], float))
        # a vertex on the box's edges lies on the outline: the pixel or one next to it (as for the points)
        def drawn(p):
            x0, y0 = min(int(round(p[0])), w - 1), min(int(round(p[1])), h - 1)
            window = img[max(y0 - 1, 0):y0 + 2, max(x0 - 1, 0):x0 + 2].reshape(-1, 3)
            return np.any(np.linalg.norm(window - BACKGROUND, axis=1) > 8)
        on = [drawn(p) for p in vpix if np.linalg.norm(p - pc) > 1.3 * r_px and 0 <= p[0] < w and 0 <= p[1] < h]
        assert len(on) > 20 and np.mean(on) > 0.9, f"{png}: {np.mean(on):.2f} of the surface's vertices on drawn pixels"
    lo, hi = pix.min(axis=0), pix.max(axis=0)
    margin = 3 * info["point_radius"] * ppm[0] + 10
    for corner in ((vx + 5, vy + 40), (vx + vw - 80, vy + vh - 5), (vx + 5, vy + vh - 5)):
        if lo[0] - margin < corner[0] < hi[0] + margin and lo[1] - margin < corner[1] < hi[1] + margin:
            continue
        d = np.linalg.norm(img[int(corner[1]), int(corner[0])] - BACKGROUND)
        assert d < 12, f"{png}: pixel {corner} is not background ({d:.0f})"
    if expect_contact:
        assert info["contacts"] > 0 and info["displacement_max"] > 1e-3, info
    # the colour bar at the right edge: a viridis ramp, dark at the bottom and light at the top
    bar_x = int(vx + vw - 32)
    top, bottom = img[int(vy + 60), bar_x], img[int(vy + vh - 60), bar_x]
    assert top.sum() > bottom.sum() + 150, f"{png}: no colour bar ({top}, {bottom})"
    return info


def run(args, **kw):
    r = subprocess.run([exe, "view", *args], capture_output=True, text=True, timeout=300, **kw)
    assert r.returncode == 0, r.stderr + r.stdout
    return r


beam = os.path.join(scenes, "beam_probe.toml")  # the default scene: the seed's beam, both ends held
block = os.path.join(os.path.dirname(os.path.abspath(__file__)), "viewer_block.toml")
size = ["--width", str(SIZE[0]), "--height", str(SIZE[1])]

if mode == "headless":
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    png, info = os.path.join(out, "headless.png"), os.path.join(out, "headless.json")
    run([block, "--screenshot", png, "--info", info, "--time", "1.5", *size], env=env)
    i1 = check_picture(png, info, expect_contact=True)
    assert i1["surface"]["drawn"], i1["surface"]
    # the points instead of the surface, on request
    pngp, infop = os.path.join(out, "points.png"), os.path.join(out, "points.json")
    run([block, "--screenshot", pngp, "--info", infop, "--time", "1.5", "--draw", "points", *size], env=env)
    ip = check_picture(pngp, infop, expect_contact=True)
    assert not ip["surface"]["drawn"], ip["surface"]
    # the surface is smooth where the points are balls: far fewer distinct shades over the object
    surf = np.asarray(Image.open(png).convert("RGB")).astype(float)
    balls = np.asarray(Image.open(pngp).convert("RGB")).astype(float)
    def edges(img):  # strong colour jumps between neighbouring pixels inside the view
        vx, vy, vw, vh = i1["viewport"]
        v = img[int(vy) + 40:int(vy + vh) - 40, int(vx) + 40:int(vx + vw) - 80]
        return (np.linalg.norm(np.diff(v, axis=1), axis=2) > 40).sum()
    assert edges(surf) < 0.5 * edges(balls), (edges(surf), edges(balls))
    # coloured by von Mises stress: the colour bar says kPa (the ramp is checked by check_picture)
    pngs, infos = os.path.join(out, "stress.png"), os.path.join(out, "stress.json")
    run([block, "--screenshot", pngs, "--info", infos, "--time", "1.5", "--colour", "von_mises", *size], env=env)
    check_picture(pngs, infos, expect_contact=True)
    # deterministic: the same frame twice
    png2, info2 = os.path.join(out, "headless2.png"), os.path.join(out, "headless2.json")
    run([block, "--screenshot", png2, "--info", info2, "--time", "1.5", *size], env=env)
    assert np.array_equal(np.asarray(Image.open(png)), np.asarray(Image.open(png2))), "headless frames differ"
    # before the probe arrives nothing is displaced and nothing touches
    png0, info0 = os.path.join(out, "headless0.png"), os.path.join(out, "headless0.json")
    run([block, "--screenshot", png0, "--info", info0, *size], env=env)
    i0 = check_picture(png0, info0, expect_contact=False)
    assert i0["contacts"] == 0 and i0["displacement_max"] == 0, i0
    assert i1["probe"]["position"][1] < i0["probe"]["position"][1] - 0.005, "the scripted probe did not come down"
    # levels of detail coloured by band (seed Fig. 6): the bands' warm colours around the probe, grey (not
    # simulated) points over most of the object
    lod = os.path.join(scenes, "half_sphere_lod.toml")
    pngb, infob = os.path.join(out, "bands.png"), os.path.join(out, "bands.json")
    run([lod, "--screenshot", pngb, "--info", infob, "--time", "0.3", "--colour", "band", *size], env=env)
    ib = json.load(open(infob))
    img = np.asarray(Image.open(pngb).convert("RGB")).astype(float)
    (pc,), _, ppm = project(ib, np.array(ib["probe"]["position"], float))
    ys, xs = np.mgrid[0:img.shape[0], 0:img.shape[1]]
    near = (xs - pc[0]) ** 2 + (ys - pc[1]) ** 2 < (6 * ib["probe"]["radius"] * ppm[0]) ** 2
    r, g, b = img[..., 0], img[..., 1], img[..., 2]
    warm = (r > g + 40) & (g > b) & (r > 90)  # T_r1 .. level colours: dark red to pale orange
    grey = (np.abs(r - g) < 12) & (np.abs(g - b) < 20) & (r > 60)
    vx, vy, vw, vh = ib["viewport"]
    inview = (xs >= vx + 0) & (ys >= vy + 30)
    assert warm[near].mean() > 0.05, f"{pngb}: no band colours around the probe ({warm[near].mean():.3f})"
    assert grey[inview].sum() > 5 * warm[inview & near].sum(), f"{pngb}: too few unsimulated (grey) points"
    # errors are named, not crashes
    r = subprocess.run([exe, "view", os.path.join(out, "missing.toml"), "--screenshot", png0], capture_output=True,
                       text=True, env=env)
    assert r.returncode == 1 and "missing.toml" in r.stderr, r.stderr
    # a reduced model (its probe's contact region in full): shown as any run, the object coloured where it moved
    reduced = os.path.join(out, "reduced.toml")
    with open(os.path.join(scenes, "cantilever_static.toml")) as f:
        text = f.read()
    with open(reduced, "w") as f:
        f.write(text + '\n[reduction]\nmodes = 12\ncache = "none"\n')
    pngr, infor = os.path.join(out, "reduced.png"), os.path.join(out, "reduced.json")
    run([reduced, "--screenshot", pngr, "--info", infor, "--time", "0.1", *size], env=env)
    check_picture(pngr, infor, expect_contact=False)
    print("headless screenshots: ok")
    sys.exit(0)

# a private X server (Xvfb), on the first free display number
if not shutil.which("Xvfb"):
    sys.exit("Xvfb is missing (Debian package xvfb; scripts/setup installs it)")
xvfb = subprocess.Popen(["Xvfb", "-displayfd", "1", "-screen", "0", f"{SIZE[0]}x{SIZE[1]}x24", "-nolisten", "tcp"],
                        stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
display = ":" + xvfb.stdout.readline().strip()
env = dict(os.environ, DISPLAY=display)
try:
    if mode == "window":
        png, info = os.path.join(out, "window.png"), os.path.join(out, "window.json")
        run([block, "--probe", "script", "--run-for", "1.6", "--screenshot", png, "--info", info, *size], env=env)
        i = check_picture(png, info, expect_contact=True)
        # the haptic loop kept its rate while the window drew (a loose bound: machines are shared)
        assert i["haptic_rate_hz"] > 500, i["haptic_rate_hz"]
        assert i["time"] > 1.0, i["time"]
        print(f"window under Xvfb: ok (haptic {i['haptic_rate_hz']:.0f} Hz, t = {i['time']:.2f} s)")
    else:
        if not shutil.which("xdotool"):
            sys.exit("xdotool is missing (Debian package xdotool; scripts/setup installs it)")
        # where things are: the same camera as the window's, from a headless frame of the same size
        hinfo = os.path.join(out, "mouse_start.json")
        run([beam, "--probe", "mouse", "--screenshot", os.path.join(out, "mouse_start.png"), "--info", hinfo, *size],
            env={k: v for k, v in env.items() if k != "DISPLAY"})
        start = json.load(open(hinfo))
        origin = np.array(start["probe"]["position"])
        r = start["probe"]["radius"]
        png, info = os.path.join(out, "mouse.png"), os.path.join(out, "mouse.json")
        for old in glob.glob(os.path.join(out, "pointhaptics-*.png")):
            os.remove(old)
        viewer = subprocess.Popen([exe, "view", beam, "--probe", "mouse", "--run-for", "7", "--screenshot", png,
                                   "--info", info, *size], env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                  text=True, cwd=out)
        time.sleep(2.0)  # the window is up

        def move_to(point):
            (p,), _, _ = project(start, point)
            subprocess.run(["xdotool", "mousemove", str(int(p[0])), str(int(p[1]))], env=env, check=True)
            time.sleep(0.4)

        # the probe stays at its origin, above the object, until the cursor moves (issue 21: it used to jump
        # to wherever the pointer was); then it follows the cursor's motion in the view plane through it,
        # anchored where it was: the cursor is put over the origin first, so that positions below are
        # where the probe goes. Down into the top face, then press, lift, and hold there until the window
        # closes
        time.sleep(0.5)
        down = origin + np.array([0.0, -2.3 * r, 0.0])
        move_to(origin)
        move_to(origin + np.array([0.0, -0.5 * r, 0.0]))
        move_to(down)
        subprocess.run(["xdotool", "mousedown", "1"], env=env, check=True)
        time.sleep(0.5)
        move_to(down + np.array([0.0, 0.6 * r, 0.0]))
        move_to(down + np.array([0.0, 1.2 * r, 0.0]))
        subprocess.run(["xdotool", "key", "s"], env=env, check=True)  # S saves a screenshot in the working folder
        stdout, stderr = viewer.communicate(timeout=60)
        subprocess.run(["xdotool", "mouseup", "1"], env=env)
        assert viewer.returncode == 0, stderr
        i = json.load(open(info))
        assert i["contacts"] > 0, f"the mouse probe holds nothing: {i}"
        assert i["displacement_max"] > 2e-3, f"the grabbed points did not come up: {i['displacement_max']}"
        check_picture(png, info, expect_contact=True)
        saved = glob.glob(os.path.join(out, "pointhaptics-*.png"))
        assert len(saved) == 1, f"the S key saved {saved}"
        assert Image.open(saved[0]).size == SIZE, Image.open(saved[0]).size
        print(f"mouse under Xvfb: ok ({i['contacts']} points held, lifted {1e3 * i['displacement_max']:.1f} mm)")
finally:
    xvfb.terminate()
    xvfb.wait(timeout=10)
