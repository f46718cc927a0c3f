"""A glove palpation scripted in Python on the knee (scenes/knee_hand.json).

The hand's pressing pose is the one the scene's own script solved (its pose and finger angles
when its press begins); the motion is Python's: the hand comes in from 80 mm away, presses in,
then rocks the index and middle fingers against each other (MCP and PIP flexion
±0.2 rad each) and lets go (back out to where it came from). The
plot shows each finger's force on the glove's actuators and the two fingers' flexion.

    PYTHONPATH=build/release/python python3 examples/python/glove_palpation.py \
        [--out docs/images] [--quick]
"""

import argparse
import math
import pathlib

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import hapsim  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[2]
INDEX, MIDDLE = 1, 2
# A glove's reading: joint_rad holds three angles per finger (abduction, MCP, PIP), thumb first.
ANGLES_PER_FINGER = 3
MCP, PIP = 1, 2


def flexion_slots(finger):
    """joint_rad indices of a finger's MCP and PIP flexion."""
    return [finger * ANGLES_PER_FINGER + MCP, finger * ANGLES_PER_FINGER + PIP]


def smooth(s):
    """0 → 1 with zero velocity at both ends."""
    s = min(max(s, 0.0), 1.0)
    return 0.5 - 0.5 * math.cos(math.pi * s)


def script(start, press, away_m, rock_rad, rock_cycles):
    """(total seconds, f(t) -> DeviceInput, phases) of the palpation, from the scene script's
    first input `start` and its pressing pose `press`."""
    p_press = press.p_world
    angles = press.joint_rad
    # The scene's script comes in along the direction it pressed: from where the hand starts.
    start = start.p_world
    out = (start - p_press) / np.linalg.norm(start - p_press)
    p_far = p_press + out * away_m
    p_stand = p_press + out * 0.02
    phases = [("approach", 0.8), ("press", 0.6), ("hold", 0.3), ("rock", 0.6 * rock_cycles),
              ("release", 0.8)]

    def at(t):
        p = p_press.copy()
        flex = angles.copy()
        t0 = 0.0
        for name, duration in phases:
            s = (t - t0) / duration
            if t < t0 + duration or name == "release":
                if name == "approach":
                    p = p_far + (p_stand - p_far) * smooth(s)
                elif name == "press":
                    p = p_stand + (p_press - p_stand) * smooth(s)
                elif name == "rock":
                    swing = rock_rad * math.sin(2.0 * math.pi * rock_cycles * s)
                    flex[flexion_slots(INDEX)] += swing
                    flex[flexion_slots(MIDDLE)] -= swing
                elif name == "release":
                    p = p_press + (p_far - p_press) * smooth(s)
                break
            t0 += duration
        return hapsim.DeviceInput(p_world=p, q_world=press.q_world, joint_rad=flex, time_s=t)

    return sum(d for _, d in phases), at, phases



def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", default=str(ROOT / "scenes" / "knee_hand.json"))
    parser.add_argument("--out", default=str(ROOT / "docs" / "images"))
    parser.add_argument("--quick", action="store_true", help="one rocking cycle (tests)")
    args = parser.parse_args()
    scene = hapsim.load_scene(args.scene)
    world = hapsim.World(scene)
    # The scene's own script: where it starts and the pose it presses with (move 0.8 s, press
    # 0.6 s in knee_hand.json: the hold begins at 1.4 s).
    start = world.script_input(0.0)
    press = start
    for i in range(1, 1401):
        press = world.script_input(i * world.dt_s)
    world = hapsim.World(scene)  # fresh, untouched by reading its script
    total_s, at, phases = script(start, press, away_m=0.08, rock_rad=0.2,
                                 rock_cycles=1 if args.quick else 3)
    steps = int(round(total_s / world.dt_s))
    t = np.arange(steps) * world.dt_s
    finger_force = np.zeros((steps, 5))
    flex = np.zeros((steps, 2))
    for i in range(steps):
        inp = at(t[i])
        world.step(inp)
        f = world.finger_force_n
        finger_force[i, : len(f)] = f
        flex[i] = inp.joint_rad[[flexion_slots(INDEX)[0], flexion_slots(MIDDLE)[0]]]

    names = ["thumb", "index", "middle", "ring", "little"]
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(9, 6), dpi=110, sharex=True,
                                      gridspec_kw={"height_ratios": [2, 1]})
    for k, name in enumerate(names):
        if finger_force[:, k].max() > 0.0:
            top.plot(t, finger_force[:, k], lw=1.4, label=f"{name} (peak {finger_force[:, k].max():.2f} N)")
    top.set_ylabel("finger actuator force (N)")
    top.set_title("Glove palpation scripted in Python on the knee (vastus medialis)")
    top.grid(alpha=0.3)
    top.legend(fontsize=8, loc="center left")
    bottom.plot(t, np.degrees(flex[:, 0]), lw=1.2, label="index MCP flexion")
    bottom.plot(t, np.degrees(flex[:, 1]), lw=1.2, label="middle MCP flexion")
    bottom.set_ylabel("flexion (deg)")
    bottom.set_xlabel("time (s)")
    bottom.grid(alpha=0.3)
    bottom.legend(fontsize=8, loc="upper left")
    t0 = 0.0
    for name, duration in phases:
        for ax in (top, bottom):
            ax.axvline(t0, color="0.8", lw=0.8)
        top.text(t0 + 0.02, 0.98, name, transform=top.get_xaxis_transform(), va="top",
                 fontsize=8, color="0.4")
        t0 += duration
    out = pathlib.Path(args.out) / "python_glove_palpation.png"
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.tight_layout()
    fig.savefig(out)
    for k, name in enumerate(names):
        print(f"{name:7s} peak {finger_force[:, k].max():.3f} N")
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
