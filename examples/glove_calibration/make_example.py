#!/usr/bin/env python3
"""A synthetic user's glove calibration session and a raw-sensor palpation (docs/glove-calibration.md).

Writes, deterministically (seeded noise), into this folder:
  procedure.json       PROC.json: the poses held (angles in degrees) and when, and the pivot window
  raw_procedure.csv    RAW.csv: what the glove reported during the procedure: tracker pose and
                       integer counts s0..s13 (layout hapsim-glove-14/1)
  palpation_angles.csv the palpation the user then does, as hand pose + joint angles j0..j14
  palpation_raw.csv    the same palpation as the glove reports it: tracker pose + counts

The synthetic user's glove (TRUE_GLOVE below: offsets, counts per radian, cross-talk) and
tracker-to-hand offset are what `hapsim calibrate glove` must recover:
  hapsim calibrate glove raw_procedure.csv --procedure procedure.json --out user.json
then `hapsim run scene.json` plays palpation_raw.csv through user.json.

Noise: Gaussian, NOISE_COUNTS (1 count) on every reading, then rounded to whole counts (an ADC);
the tracker's position has 0.3 mm of noise. Python's standard library only.
"""
import json
import math
import os
import random

HERE = os.path.dirname(os.path.abspath(__file__))
SEED = 2026
NOISE_COUNTS = 1.0
TRACKER_NOISE_M = 3e-4
RATE_HZ = 50.0

# Layout hapsim-glove-14/1 (src/hapsim/device/glove_sensor_layout.cpp): sensor -> (joint, coupled joint).
LAYOUT = [(0, 1), (1, None), (2, None), (4, None), (5, None), (7, None), (8, None), (10, None),
          (11, None), (13, None), (14, None), (3, 4), (9, 10), (12, 9)]
# The user's glove: offset (counts), counts per radian, and the coupled joint's counts per radian.
TRUE_GLOVE = []
for s, (joint, coupled) in enumerate(LAYOUT):
    a = (70.0 + 4.0 * ((s * 5) % 7)) * (-1.0 if s in (12, 13) else 1.0)
    b = 0.0 if coupled is None else 0.15 * a
    if s == 13:
        b = -0.9 * a  # the ring-little spread sees the angle between the two fingers
    TRUE_GLOVE.append((55.0 + 9.0 * ((s * 3) % 5), a, b))
# The hand frame's origin in the tracker's frame (the tracker sits on the back of the wrist).
TRACKER_TO_HAND_M = (-0.035, 0.0, -0.025)


def deg(**angles):
    out = [0.0] * 15
    for name, value in angles.items():
        out[int(name[1:])] = math.radians(value)
    return out


POSES = [
    ("flat", "hand flat on the table, fingers together", deg()),
    ("fist", "a closed fist, thumb over the fingers",
     deg(j0=20, j1=40, j2=50, j4=90, j5=100, j7=90, j8=100, j10=90, j11=100, j13=90, j14=100)),
    ("spread", "hand flat, fingers spread wide", deg(j0=35, j3=15, j9=-15, j12=-30)),
    ("thumb_opposition", "thumb tip across the palm towards the little finger's base",
     deg(j0=60, j1=30, j2=30)),
    ("tabletop", "fingers straight, bent 90 deg at the knuckles",
     deg(j1=20, j4=90, j7=90, j10=90, j13=90)),
    ("hook", "knuckles straight, middle joints bent 90 deg", deg(j2=60, j5=90, j8=90, j11=90, j14=90)),
    ("little_out", "little finger out alone, index half bent and out, thumb bent",
     deg(j1=50, j3=10, j4=45, j10=45, j12=-25)),
]


def quat_mul(a, b):
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return (aw * bw - ax * bx - ay * by - az * bz, aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx, aw * bz + ax * by - ay * bx + az * bw)


def rotate(q, v):
    p = quat_mul(quat_mul(q, (0.0, v[0], v[1], v[2])), (q[0], -q[1], -q[2], -q[3]))
    return p[1:]


def axis_angle(axis, angle):
    s = math.sin(angle / 2)
    return (math.cos(angle / 2), axis[0] * s, axis[1] * s, axis[2] * s)


def counts(angles, rng, noise=NOISE_COUNTS):
    out = []
    for s, (joint, coupled) in enumerate(LAYOUT):
        offset, a, b = TRUE_GLOVE[s]
        c = offset + a * angles[joint] + (b * angles[coupled] if coupled is not None else 0.0)
        out.append(int(round(c + rng.gauss(0.0, noise))))
    return out


def tracker_pose(p_hand, q_hand, rng):
    # The tracker for a hand pose: X_world_tracker = X_world_hand * inverse(X_tracker_hand).
    r = rotate(q_hand, TRACKER_TO_HAND_M)
    p = [p_hand[k] - r[k] + rng.gauss(0.0, TRACKER_NOISE_M) for k in range(3)]
    return p, q_hand


def row(t, p, q, values, fmt="%d"):
    return ",".join(["%.3f" % t] + ["%.6f" % x for x in p] + ["%.9f" % x for x in q] +
                    [fmt % v for v in values])


def main():
    rng = random.Random(SEED)
    header = "t,x,y,z,qw,qx,qy,qz," + ",".join("s%d" % s for s in range(len(LAYOUT)))
    lines = ["# hapsim glove calibration procedure, synthetic user (examples/glove_calibration/make_example.py)",
             "# units: m", header]
    dt = 1.0 / RATE_HZ
    t = 0.0
    previous = deg()
    p_rest = (0.0, 0.0, 0.1)
    identity = (1.0, 0.0, 0.0, 0.0)
    procedure = {"$schema": "", "format": "hapsim-glove-procedure/1", "layout": "hapsim-glove-14/1",
                 "description": "Synthetic user: seven poses held 1.5 s each after 0.8 s to get there, then "
                                "4 s rocking the heel of the palm on a fixed point (the pivot).",
                 "poses": []}
    del procedure["$schema"]
    for name, description, target in POSES:
        for k in range(1, 41):  # 0.8 s to move into the pose (not held: outside its window)
            u = k / 40.0
            angles = [a + (b - a) * u for a, b in zip(previous, target)]
            p, q = tracker_pose(p_rest, identity, rng)
            lines.append(row(t, p, q, counts(angles, rng)))
            t += dt
        start = t
        for _ in range(75):  # 1.5 s held
            p, q = tracker_pose(p_rest, identity, rng)
            lines.append(row(t, p, q, counts(target, rng)))
            t += dt
        procedure["poses"].append({
            "name": name, "description": description,
            "from_s": round(start + 0.2, 3), "to_s": round(t - dt, 3),  # 0.2 s to settle
            "angles_deg": {"j%d" % j: round(math.degrees(a), 6) for j, a in enumerate(target) if a != 0.0}})
        previous = target
    # Pivot: the hand flat, its frame's origin (the heel of the palm) on a fixed point, rocked.
    pivot_point = (0.05, 0.02, 0.0)
    start = t
    for k in range(200):
        u = k / 200.0
        q = quat_mul(axis_angle((1, 0, 0), 0.45 * math.sin(2 * math.pi * u)),
                     axis_angle((0, 1, 0), 0.35 * math.sin(4 * math.pi * u)))
        p, q = tracker_pose(pivot_point, q, rng)
        lines.append(row(t, p, q, counts(deg(), rng)))
        t += dt
    procedure["pivot"] = {"from_s": round(start, 3), "to_s": round(t - dt, 3),
                          "description": "heel of the palm on the table's corner, hand rocked"}
    with open(os.path.join(HERE, "raw_procedure.csv"), "w") as f:
        f.write("\n".join(lines) + "\n")
    with open(os.path.join(HERE, "procedure.json"), "w") as f:
        json.dump(procedure, f, indent=2)
        f.write("\n")

    # The palpation: palm down over the pad, the index presses (MCP 40, PIP 30 deg) and lets go,
    # the other fingers curling a little (clear of the pad) so every sensor moves; 1 kHz rows would be 14 columns of
    # counts per ms: a glove reports at 100 Hz, the trajectory interpolates between rows.
    p_hand = (0.0, 0.0, 0.075)
    angle_lines = ["# the palpation as angles (source of palpation_raw.csv)", "# units: m",
                   "t,x,y,z,qw,qx,qy,qz," + ",".join("j%d" % j for j in range(15))]
    raw_lines = ["# the palpation as the glove reports it: tracker pose and counts", "# units: m", header]
    n = 400
    for k in range(n + 1):
        tt = k * 0.01
        press = 0.5 - 0.5 * math.cos(2 * math.pi * tt / 4.0)  # 0 -> 1 at 2 s -> 0 at 4 s
        angles = deg(j0=10 + 10 * press, j1=20 + 10 * press, j2=20, j3=5 * press, j4=40 * press,
                     j5=30 * press, j7=10 + 5 * press, j8=15 + 5 * press, j9=-5,
                     j10=10 + 5 * press, j11=15 + 5 * press, j12=-10, j13=10 + 5 * press,
                     j14=15 + 5 * press)
        angle_lines.append(row(tt, p_hand, identity, angles, "%.9f"))
        p, q = tracker_pose(p_hand, identity, rng)
        raw_lines.append(row(tt, p, q, counts(angles, rng)))
    with open(os.path.join(HERE, "palpation_angles.csv"), "w") as f:
        f.write("\n".join(angle_lines) + "\n")
    with open(os.path.join(HERE, "palpation_raw.csv"), "w") as f:
        f.write("\n".join(raw_lines) + "\n")


if __name__ == "__main__":
    main()
