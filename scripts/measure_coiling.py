#!/usr/bin/env python3
"""A falling viscous rope's coiling frequency, from a run's particle frames, beside Ribe 2004's three scalings.

  PYTHONPATH=build/python python3 scripts/measure_coiling.py RUN_DIR [--start S] [--end S]

The run is a scene of one emitter pointing down at a plate (scenes/honey.json). Over the frames from --start (0.5 s
by default, the rope's first landing past) to --end (the emitter's stop), it reads at each frame:

- the pile's top: the highest layer a spacing thick, within 3 cm of the spout's axis, that holds more than three
  times the rope's particles a layer (the rope's count from the layers just under the spout);
- the rope's place: the mean of its particles in a band from 30% to 60% of the way up from the pile's top to the
  spout, and its angle about the spout's axis.

The frequency is the unwrapped angle's least-squares slope (Omega, rad/s), the turns its change. Ribe's scalings
(Ribe 2004; Ribe, Habibi and Bonn 2012) take the rope where it meets the pile: its speed U1 (the band 10% to 30% of
the way up), its radius a1 = sqrt(Q / (pi U1)), Q the emitter's flux, and the fall H from the spout to the pile's
top: viscous U1 / H, gravitational (g Q^3 / (nu a1^8))^(1/4) and inertial (Q^4 / (nu a1^10))^(1/3), with the height
in Ribe's units H (g / nu^2)^(1/3). tests/sim/coiling_test.py holds the honey scene's Omega between the viscous and
the inertial scalings; docs/viscosity.md has its figures.
"""
import argparse
import json
import math
import os
import sys

import numpy as np

try:
    import surge
except ImportError:
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "build", "python"))
    import surge

AXIS_REACH = 0.03  # m: the particles this near the spout's axis are the rope's and the pile's


def measure(run_dir, start=0.5, end=None):
    scene = json.load(open(os.path.join(run_dir, "scene.json")))
    if scene["dimensions"] != 3 or len(scene.get("emitters", [])) != 1:
        raise ValueError(f"{run_dir}: a 3D scene of one emitter is measured")
    emitter = scene["emitters"][0]
    spout = np.array(emitter["position"], dtype=float)
    direction = np.array(emitter["direction"], dtype=float)
    if direction[1] > -0.99 * np.linalg.norm(direction):
        raise ValueError(f"{run_dir}: emitters[0].direction must point down")
    spacing = scene["particle_spacing"]
    fps = scene["output"]["fps"]
    nu = scene["fluids"][0]["viscosity"]
    g = abs(scene["gravity"][1])
    flux = math.pi * emitter["radius"] ** 2 * emitter["speed"]
    end = emitter["stop"] if end is None else end
    frames = range(int(round(start * fps)), int(round(end * fps)) + 1)

    angles, tops, speeds = [], [], []
    for frame in frames:
        p = surge.read_frame(os.path.join(run_dir, "particles", f"frame_{frame:05d}.ply"))
        x, y, z = p["x"] - spout[0], p["y"], p["z"] - spout[2]
        near = np.hypot(x, z) < AXIS_REACH
        layers = np.arange(0, spout[1], spacing)
        counts = np.histogram(y[near], bins=layers)[0]
        rope = np.median(counts[-4:])
        full = np.nonzero(counts > 3 * max(rope, 1))[0]
        top = layers[full[-1] + 1] if len(full) else layers[0]
        fall = spout[1] - top
        band = near & (y > top + 0.3 * fall) & (y < top + 0.6 * fall)
        foot = near & (y > top + 0.1 * fall) & (y < top + 0.3 * fall)
        if not band.any() or not foot.any():
            raise ValueError(f"{run_dir}: frame {frame} has no rope between the pile and the spout")
        angles.append(math.atan2(z[band].mean(), x[band].mean()))
        tops.append(top)
        speeds.append(-p["vy"][foot].mean())

    t = np.array(frames) / fps
    angle = np.unwrap(np.array(angles))
    omega = np.polyfit(t, angle, 1)[0]
    u1, height = float(np.mean(speeds)), spout[1] - float(np.mean(tops))
    a1 = math.sqrt(flux / (math.pi * u1))
    return {
        "start": t[0], "end": t[-1], "turns": (angle[-1] - angle[0]) / (2 * math.pi), "omega": omega,
        "hz": omega / (2 * math.pi), "U1": u1, "a1": a1, "H": height, "Q": flux, "nu": nu,
        "viscous": u1 / height,
        "gravitational": (g * flux ** 3 / (nu * a1 ** 8)) ** 0.25,
        "inertial": (flux ** 4 / (nu * a1 ** 10)) ** (1 / 3),
        "H_hat": height * (g / nu ** 2) ** (1 / 3),
    }


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("run_dir")
    parser.add_argument("--start", type=float, default=0.5, help="first time measured, s (default 0.5)")
    parser.add_argument("--end", type=float, default=None, help="last time measured, s (default the emitter's stop)")
    args = parser.parse_args()
    m = measure(args.run_dir, args.start, args.end)
    direction = "counter-clockwise" if m["omega"] > 0 else "clockwise"
    print(f"{args.run_dir}, {m['start']:.2f} to {m['end']:.2f} s: {abs(m['turns']):.2f} turns {direction} seen from "
          f"above, {abs(m['hz']):.2f} Hz, Omega {abs(m['omega']):.1f} rad/s")
    print(f"rope at the pile: U1 {m['U1']:.3f} m/s, a1 {1e3 * m['a1']:.2f} mm (Q {1e6 * m['Q']:.2f} cm^3/s); "
          f"fall H {1e2 * m['H']:.2f} cm; H (g / nu^2)^(1/3) = {m['H_hat']:.2f}")
    print("| regime | scaling | rad/s | measured over it |")
    print("|---|---|---|---|")
    for name, formula in (("viscous", "U1 / H"), ("gravitational", "(g Q^3 / (nu a1^8))^(1/4)"),
                          ("inertial", "(Q^4 / (nu a1^10))^(1/3)")):
        print(f"| {name} | {formula} | {m[name]:.1f} | {abs(m['omega']) / m[name]:.2f} |")


if __name__ == "__main__":
    main()
