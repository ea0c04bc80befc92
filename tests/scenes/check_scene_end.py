"""Whether a scene's run ended as a scene should (tests/scenes/scenes_test.sh): every frame written, and the fluid
at rest or near it, or, fed by an emitter or driven by a moving collider until the end, steady.

  check_scene_end.py SCENE.json RUN_DIR   prints one line of figures; exit 0 when it holds, 1 when not.

Near rest: the particles' RMS speed at the end is under a fifth of the speed of a fall through the tank,
sqrt(2 g H) (without gravity, of a capillary wave a spacing long). A dam break still sloshing at its end reads up to 0.15 of it; the pool that boiled under too long a
PBF step (issue 32) read 0.6. Steady: over the last second the fluid's kinetic energy stays within a quarter of
its mean (a pour, a river and a fountain read within 3%, couette's dragged channel 0.8%); one that diverges or boils
climbs. Stirred (a fluid set moving without gravity): its kinetic energy falls, never above its start by 5%.
"""
import csv
import json
import math
import sys

scene = json.load(open(sys.argv[1]))
rows = list(csv.DictReader(open(sys.argv[2] + "/stats.csv")))
output = scene.get("output", {})
frames, fps = output.get("frames", 120), output.get("fps", 30)
end = frames / fps
spacing, dims = scene["particle_spacing"], scene["dimensions"]
rest_density = scene.get("solver", {}).get("rest_density", 1000)
gravity = math.sqrt(sum(g * g for g in scene.get("gravity", [0, -9.81, 0])[:dims]))
height = scene["domain"]["max"][1] - scene["domain"]["min"][1]
fall = math.sqrt(2 * gravity * height)
# Without gravity, surface tension's speed: a capillary wave a spacing long, sqrt(2 sigma / (rho_0 dx)).
sigma = max([f.get("surface_tension", 0) for f in scene.get("fluids", [])] or [0])
fall = max(fall, math.sqrt(2 * sigma / (rest_density * spacing)))


def rms(row):
    mass = int(row["particles"]) * rest_density * spacing ** dims
    return math.sqrt(2 * float(row["kinetic_energy"]) / mass) if mass > 0 else 0.0


last = int(rows[-1]["frame"])
if last != frames:
    print(f"stopped at frame {last} of {frames}")
    sys.exit(1)
fed = any(e.get("stop", 0) <= 0 or e["stop"] >= end for e in scene.get("emitters", []))
# Driven: a collider keyframed to move until the end (couette's plate) keeps the fluid moving, steadily.
driven = any(len(c.get("motion", [])) > 1 and c["motion"][-1]["time"] >= end and
             c["motion"][-1].get("position") != c["motion"][0].get("position") for c in scene.get("colliders", []))
if fed or driven:
    energy = [float(r["kinetic_energy"]) for r in rows[-(int(fps) + 1):]]
    mean = sum(energy) / len(energy)
    spread = max(abs(e - mean) for e in energy) / mean if mean > 0 else 0.0
    print(f"{'fed' if fed else 'driven'} to the end: kinetic energy over the last second {min(energy):.4g} to {max(energy):.4g} J "
          f"({100 * spread:.1f}% about its mean, at most 25%)")
    sys.exit(0 if spread <= 0.25 else 1)
# Stirred: a fluid set moving without gravity or surface tension (taylor_green's vortex) only loses its energy to
# viscosity; it may gain what a jittered start's compression gives back (3.7% of the vortex's, docs/viscosity.md).
stirred = gravity == 0 and sigma == 0 and any(f.get("velocity_field") or any(f.get("velocity", [])) for f in scene.get("fluids", []))
if stirred:
    energy = [float(r["kinetic_energy"]) for r in rows]
    ok = max(energy) <= 1.05 * energy[0] and energy[-1] < energy[0]
    print(f"stirred: kinetic energy {energy[0]:.4g} J at the start, at most {max(energy):.4g} (at most 5% more), "
          f"{energy[-1]:.4g} at the end (less)")
    sys.exit(0 if ok else 1)
speed = rms(rows[-1])
print(f"RMS speed at the end {speed:.3f} m/s, {speed / fall:.3f} of a fall through the tank ({fall:.2f} m/s; "
      f"at most 0.2), peak {max(rms(r) for r in rows):.3f}")
sys.exit(0 if speed <= 0.2 * fall else 1)
