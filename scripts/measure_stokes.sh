#!/usr/bin/env bash
# The runs behind docs/viscosity.md's "Solids moving through a viscous fluid": a ball settling through a viscous
# fluid (Stokes), a sphere and a disc moved through it at a set speed (their drag), and a disc spinning in it (its
# torque), each printed beside the value it is measured against. The 2D disc's settling at 1 and 2 ms is a test
# (Bodies.ADiscSettlesBetweenWallsAtFaxensSpeedInDfsph), and so is the ball in the sphere of fluid as it passes
# the centre late, in frames 24 to 40 (Bodies.ABallSettlesThroughASphereOfHoneyAtStokesSpeedInDfsph3D); the runs
# here measure from frame 8, through the fluid's slump (docs/viscosity.md).
# About 15 minutes on two cores (the 3D runs; the finest ball alone 6).
#
#   scripts/measure_stokes.sh [SURGE_BINARY]
set -euo pipefail
surge=${1:-build/apps/surge}
work=out/measure_stokes
mkdir -p "$work"

run() {  # run NAME JSON [--set ...]: simulates JSON into $work/NAME
  local name=$1 json=$2
  shift 2
  printf '%s\n' "$json" > "$work/$name.json"
  "$surge" sim "$work/$name.json" --out "$work/$name" --quiet "$@"
}
# column COLUMN FILE: a CSV column by its header name, one value a line (the header dropped).
column() { awk -F, -v want="$1" 'NR == 1 { for (i = 1; i <= NF; ++i) if ($i == want) c = i; next } { print $c }' "$2"; }

# 3D: a ball of radius a = 0.05 (4 spacings) in a tank 0.5 x 0.6 x 0.5 full of fluid; the wall factor for a
# sphere on the axis of a square duct of half-width l = 0.25 is about 1 - 1.903 a / l = 0.62.
tank3='"dimensions": 3, "domain": {"min": [0, 0, 0], "max": [0.5, 0.6, 0.5]}, "particle_spacing": 0.0125,
  "gravity": [0, -9.81, 0], "solver": {"method": "dfsph"}'
fluid3() { echo "\"fluids\": [{\"box\": {\"min\": [0, 0, 0], \"max\": [0.5, 0.6, 0.5]}, \"viscosity\": $1}]"; }

run steel "{\"name\": \"steel\", $tank3, $(fluid3 0.37), \"output\": {\"fps\": 40, \"frames\": 40},
  \"bodies\": [{\"name\": \"ball\", \"shape\": \"sphere\", \"position\": [0.25, 0.35, 0.25], \"radius\": 0.05,
                \"density\": 7800}]}"
awk -F, '$2 == "ball" && ($1 == 20 || $1 == 40) { y[$1] = $4; f[$1] = $17 }
  END { u = (y[20] - y[40]) / 0.5; stokes = 2 * 6800 * 9.81 * 0.05 ^ 2 / (9 * 1000 * 0.37);
        printf "steel ball (7800, nu 0.37): settles at %.4f m/s, Stokes %.4f, with the wall factor about %.4f; fluid force %.1f N against its weight %.2f N\n",
               u, stokes, 0.62 * stokes, f[40], 7800 * 4 / 3 * 3.14159265 * 0.05 ^ 3 * 9.81 }' "$work/steel/bodies.csv"

run moved "{\"name\": \"moved\", $tank3, $(fluid3 0.37), \"output\": {\"fps\": 40, \"frames\": 16},
  \"colliders\": [{\"name\": \"ball\", \"shape\": \"sphere\", \"position\": [0.25, 0.35, 0.25], \"radius\": 0.05,
    \"motion\": [{\"time\": 0, \"position\": [0.25, 0.35, 0.25]}, {\"time\": 1, \"position\": [0.25, 0.25, 0.25]}]}]}"
column fy "$work/moved/colliders.csv" | tail -8 | awk '{ s += $1 } END {
  buoyancy = 1000 * 4 / 3 * 3.14159265 * 0.05 ^ 3 * 9.81; stokes = 6 * 3.14159265 * 370 * 0.05 * 0.1;
  printf "sphere moved at 0.1 m/s: drag %.1f N (force %.1f less buoyancy %.2f), Stokes %.1f N, with the wall factor about %.0f\n",
         s / NR - buoyancy, s / NR, buoyancy, stokes, stokes / 0.62 }'

run light "{\"name\": \"light\", $tank3, $(fluid3 0.136), \"output\": {\"fps\": 40, \"frames\": 12},
  \"bodies\": [{\"name\": \"ball\", \"shape\": \"sphere\", \"position\": [0.25, 0.35, 0.25], \"radius\": 0.05,
                \"density\": 1500}]}"
awk -F, '$2 == "ball" { if ($11 < lo) lo = $11; if ($11 > hi) hi = $11 }
  END { printf "light ball (1500, nu 0.136): vertical velocity between %.3f and %.3f m/s over 12 frames, Stokes with the wall factor about %.4f\n",
               lo, hi, 0.62 * 2 * 500 * 9.81 * 0.05 ^ 2 / (9 * 136) }' "$work/light/bodies.csv"

# 3D: the steel ball at the centre of a sphere of radius 0.25 full of fluid (a container collider), for which
# the wall factor is exact at the centre (Happel and Brenner): K = 1.756 at a / b = 0.2. At 2 ms steps.
run jar "{\"name\": \"jar\", \"dimensions\": 3, \"domain\": {\"min\": [0, 0, 0], \"max\": [0.52, 0.52, 0.52]},
  \"particle_spacing\": 0.0125, \"gravity\": [0, -9.81, 0], \"solver\": {\"method\": \"dfsph\", \"time_step\": 0.002},
  \"fluids\": [{\"box\": {\"min\": [0, 0, 0], \"max\": [0.52, 0.52, 0.52]}, \"viscosity\": 0.37}], \"output\": {\"fps\": 40, \"frames\": 24},
  \"colliders\": [{\"name\": \"jar\", \"shape\": \"sphere\", \"container\": 1, \"position\": [0.26, 0.26, 0.26], \"radius\": 0.25}],
  \"bodies\": [{\"name\": \"ball\", \"shape\": \"sphere\", \"position\": [0.26, 0.26, 0.26], \"radius\": 0.05, \"density\": 7800}]}"
awk -F, '$2 == "ball" { y[$1] = $4 } END { u = (y[8] - y[24]) / 0.4; stokes = 2 * 6800 * 9.81 * 0.05 ^ 2 / (9 * 370);
  l = 0.2; K = (1 - l ^ 5) / (1 - 2.25 * l + 2.5 * l ^ 3 - 2.25 * l ^ 5 + l ^ 6);
  printf "steel ball in a sphere of fluid, 2 ms steps: settles at %.4f m/s, Stokes %.4f, with the container %.4f (%.3f)\n",
         u, stokes, stokes / K, u * K / stokes }' "$work/jar/bodies.csv"

# The same ball started 0.045 above the centre, so that it passes the centre midway through frames 8 to 24 (the
# container's factor holds at the centre): at 1 ms steps and 4 and 6 spacings a radius (30,722 and 106,435
# particles; the second about 2 minutes), and at 0.5 ms and 8 (255,690 particles, about 6 minutes).
for run in 0.0125:0.001 0.008333333:0.001 0.00625:0.0005; do
  spacing=${run%:*} step=${run#*:}
  run "jar_centred_$spacing" "{\"name\": \"jar\", \"dimensions\": 3, \"domain\": {\"min\": [0, 0, 0], \"max\": [0.52, 0.52, 0.52]},
    \"particle_spacing\": $spacing, \"gravity\": [0, -9.81, 0], \"solver\": {\"method\": \"dfsph\", \"time_step\": $step},
    \"fluids\": [{\"box\": {\"min\": [0, 0, 0], \"max\": [0.52, 0.52, 0.52]}, \"viscosity\": 0.37}], \"output\": {\"fps\": 40, \"frames\": 24},
    \"colliders\": [{\"name\": \"jar\", \"shape\": \"sphere\", \"container\": 1, \"position\": [0.26, 0.26, 0.26], \"radius\": 0.25}],
    \"bodies\": [{\"name\": \"ball\", \"shape\": \"sphere\", \"position\": [0.26, 0.305, 0.26], \"radius\": 0.05, \"density\": 7800}]}"
  awk -F, -v s="$spacing" -v dt="$step" '$2 == "ball" { y[$1] = $4 } END { u = (y[8] - y[24]) / 0.4; stokes = 2 * 6800 * 9.81 * 0.05 ^ 2 / (9 * 370);
    l = 0.2; K = (1 - l ^ 5) / (1 - 2.25 * l + 2.5 * l ^ 3 - 2.25 * l ^ 5 + l ^ 6);
    printf "steel ball through the centre of a sphere of fluid, steps of %s s, spacing %s: %.4f m/s, with the container %.4f (%.3f)\n",
           dt, s, u, stokes / K, u * K / stokes }' "$work/jar_centred_$spacing/bodies.csv"
done

# 2D: a steel disc of radius 0.05 settling down the middle of a channel 0.5 wide and 1.2 tall (Faxen's drag for a
# cylinder between two walls carries its weight less buoyancy), at DFSPH's own step and at 1 ms (the test's).
for step in 0 0.001; do
  run "settle_$step" "{\"name\": \"settle\", \"dimensions\": 2, \"domain\": {\"min\": [0, 0], \"max\": [0.5, 1.2]},
    \"particle_spacing\": 0.0125, \"gravity\": [0, -9.81], \"solver\": {\"method\": \"dfsph\", \"time_step\": $step},
    \"fluids\": [{\"box\": {\"min\": [0, 0], \"max\": [0.5, 1.2]}, \"viscosity\": 0.37}], \"output\": {\"fps\": 40, \"frames\": 32},
    \"bodies\": [{\"name\": \"disc\", \"shape\": \"sphere\", \"position\": [0.25, 0.8], \"radius\": 0.05, \"density\": 7800}]}"
  awk -F, -v s="$step" '$2 == "disc" { y[$1] = $4 } END { u = (y[8] - y[32]) / 0.6;
    a = 0.05; l = 0.25; r = a / l; faxen = 6800 * 9.81 * 3.14159265 * a ^ 2 / (4 * 3.14159265 * 370 / (log(l / a) - 0.9157 + 1.7244 * r ^ 2 - 1.7302 * r ^ 4));
    printf "steel disc settling between walls, step %s (0: DFSPH own): %.4f m/s, Faxen %.4f (%.3f)\n", s, u, faxen, u / faxen }' "$work/settle_$step/bodies.csv"
done

# 2D: a disc of radius 0.05 moved at 0.1 m/s along the middle of a channel 0.5 wide and 2 long (Faxen's drag for
# a cylinder midway between two walls), and the same disc spinning at pi/2 rad/s in a 0.5 m box (circular
# Couette's torque, the box taken as a cylinder of radius 0.25).
faxen=$(awk 'BEGIN { l = 0.25; a = 0.05; r = a / l;
  printf "%.1f", 4 * 3.14159265 * 370 * 0.1 / (log(l / a) - 0.9157 + 1.7244 * r ^ 2 - 1.7302 * r ^ 4) }')
for method in dfsph pbf wcsph; do
  for spacing in 0.0125 0.00625; do
    [[ $method != dfsph && $spacing != 0.0125 ]] && continue
    run "disc_${method}_$spacing" "{\"name\": \"disc\", \"dimensions\": 2, \"domain\": {\"min\": [0, 0], \"max\": [0.5, 2.0]},
      \"particle_spacing\": $spacing, \"gravity\": [0, 0], \"solver\": {\"method\": \"$method\"},
      \"fluids\": [{\"box\": {\"min\": [0, 0], \"max\": [0.5, 2.0]}, \"viscosity\": 0.37}], \"output\": {\"fps\": 40, \"frames\": 16},
      \"colliders\": [{\"name\": \"disc\", \"shape\": \"sphere\", \"position\": [0.25, 1.0], \"radius\": 0.05,
        \"motion\": [{\"time\": 0, \"position\": [0.25, 1.0]}, {\"time\": 1, \"position\": [0.25, 0.9]}]}]}"
    column fy "$work/disc_${method}_$spacing/colliders.csv" | tail -3 |
      awk -v m="$method" -v s="$spacing" -v f="$faxen" '{ t += $1 } END {
        printf "disc moved at 0.1 m/s, %s, spacing %s: drag %.0f N/m, Faxen %s\n", m, s, t / NR, f }'
  done
  run "spin_$method" "{\"name\": \"spin\", \"dimensions\": 2, \"domain\": {\"min\": [0, 0], \"max\": [0.5, 0.5]},
    \"particle_spacing\": 0.0125, \"gravity\": [0, 0], \"solver\": {\"method\": \"$method\"},
    \"fluids\": [{\"box\": {\"min\": [0, 0], \"max\": [0.5, 0.5]}, \"viscosity\": 0.37}], \"output\": {\"fps\": 40, \"frames\": 12},
    \"colliders\": [{\"name\": \"disc\", \"shape\": \"sphere\", \"position\": [0.25, 0.25], \"radius\": 0.05,
      \"motion\": [{\"time\": 0, \"position\": [0.25, 0.25]},
                 {\"time\": 1, \"position\": [0.25, 0.25], \"rotation\": {\"degrees\": 90}}]}]}"
  column tz "$work/spin_$method/colliders.csv" | tail -2 | awk -v m="$method" '{ t += $1 } END {
    a = 0.05; b = 0.25; exact = 4 * 3.14159265 * 370 * 1.5707963 * a ^ 2 * b ^ 2 / (b ^ 2 - a ^ 2);
    printf "disc spinning at pi/2 rad/s, %s: torque %.2f N m/m, circular Couette %.2f\n", m, -t / NR, exact }'
done
