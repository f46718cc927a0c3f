#!/usr/bin/env python3
"""Writes the committed seed corpus of the fuzz targets (fuzz/corpus/<target>/, docs/fuzzing.md).

Small on purpose: one valid input per target and the crash-prone shapes around it (empty, short,
long, NaN, infinities, huge values, negative and out-of-range integers, wrong keys). The layouts
follow the harnesses' FieldReader order (fuzz/*_fuzz.cpp): a control byte, then the message's
fields in IDL order, little-endian.

    python3 fuzz/make_seed_corpus.py        # rewrites fuzz/corpus/
"""
import math
import pathlib
import shutil
import struct

HERE = pathlib.Path(__file__).resolve().parent
CORPUS = HERE / "corpus"
NAN = float("nan")
INF = float("inf")
DEVICE = 3
SCENE = 0x68617073696D2121


def write(target, name, data):
    folder = CORPUS / target
    folder.mkdir(parents=True, exist_ok=True)
    (folder / name).write_bytes(bytes(data))


# --- legacy_packet: raw datagrams (also read as a length-prefixed stream by the harness) ------
def legacy(*values):
    return struct.pack(">4i", *values)


def legacy_seeds():
    t = "legacy_packet"
    write(t, "empty", b"")
    write(t, "one_byte", b"\x10")
    write(t, "short_15", legacy(0, 2500, 5000, 10000)[:15])
    write(t, "valid_quarters", legacy(0, 2500, 5000, 10000))
    write(t, "valid_full_scale", legacy(10000, 10000, 10000, 10000))
    write(t, "over_full_scale", legacy(0, 0, 0, 10001))
    write(t, "negative", legacy(-1, 0, 0, 0))
    write(t, "int32_min", legacy(-(2**31), 0, 0, 0))
    write(t, "int32_max", legacy(2**31 - 1, 0, 0, 0))
    write(t, "long_17", legacy(1, 2, 3, 4) + b"\x00")
    write(t, "long_64", legacy(1, 2, 3, 4) * 4)
    # A stream: [16][valid] [5][junk] [16][out of range] [16][valid] [0][] [23][long]
    stream = (b"\x10" + legacy(100, 200, 300, 400) + b"\x05" + b"junk!" + b"\x10" +
              legacy(0, 99999, 0, 0) + b"\x10" + legacy(4000, 3000, 2000, 1000) + b"\x00" +
              b"\x17" + bytes(range(23)))
    write(t, "stream_mixed", stream)
    # Forces as doubles for the round trip (4 forces, then the maximum).
    write(t, "doubles_nan_inf", struct.pack("<5d", NAN, INF, -INF, -1.0, 4.0))
    write(t, "doubles_huge_max", struct.pack("<5d", 1.0, 2.0, 1e308, 0.0, 1e308))
    write(t, "doubles_tiny_max", struct.pack("<5d", 1e-320, 1.0, 0.0, 1e-310, 5e-324))


# --- local_model: control, hapsim_msg_LocalModel fields, device sequence now, probe ----------
def local_model(control=0b11, device=DEVICE, finger=0, model_seq=2, device_seq=5, scene=SCENE,
                sim_time=0.005, x0=(0.0, 0.0, -0.002), v0=(0.0, 0.0, 0.0), f0=(0.0, 0.0, 2.0),
                k=(800.0, 0, 0, 0, 800.0, 0, 0, 0, 800.0), b=(0.5, 0, 0, 0, 0.5, 0, 0, 0, 0.5),
                normal=(0.0, 0.0, 1.0), radius=0.01, valid=1, now=5, probe=(0.0, 0.0, -0.003)):
    return (struct.pack("<BHHQQQd", control, device, finger, model_seq, device_seq, scene,
                        sim_time) +
            struct.pack("<3d3d3d9d9d3dd", *x0, *v0, *f0, *k, *b, *normal, radius) +
            struct.pack("<BQ3d", valid, now, *probe))


def local_model_seeds():
    t = "local_model"
    full = local_model()
    write(t, "empty", b"")
    write(t, "control_only", b"\x03")
    write(t, "short_half", full[: len(full) // 2])
    write(t, "valid_press", full)
    write(t, "valid_free_space", local_model(normal=(0.0, 0.0, 0.0), valid=0))
    write(t, "nan_f0", local_model(f0=(0.0, NAN, 2.0)))
    write(t, "inf_stiffness", local_model(k=(INF, 0, 0, 0, 1, 0, 0, 0, 1)))
    write(t, "huge_x0", local_model(x0=(1e308, 0.0, 0.0)))
    write(t, "huge_within_limits", local_model(x0=(99.0, -99.0, 99.0),
                                               k=(1e6, 0, 0, 0, 1e6, 0, 0, 0, 1e6),
                                               f0=(0.0, 0.0, 999.0), radius=1.0,
                                               probe=(99.0, -99.0, 98.5)))
    write(t, "negative_diagonal", local_model(k=(-1.0, 0, 0, 0, 800.0, 0, 0, 0, 800.0)))
    write(t, "asymmetric_stiffness", local_model(k=(800.0, 5e5, 0, -5e5, 800.0, 0, 0, 0, 800.0)))
    write(t, "non_unit_normal", local_model(normal=(0.0, 0.0, 2.0)))
    write(t, "negative_radius", local_model(radius=-0.01))
    write(t, "finger_out_of_range", local_model(finger=7))
    write(t, "other_scene", local_model(control=0b10, scene=SCENE ^ 1))
    write(t, "future_device_sequence", local_model(control=0, device_seq=50, now=5))
    write(t, "stale", local_model(control=0b01, device_seq=5, now=5 + 501))
    write(t, "nan_probe", local_model(probe=(NAN, 0.0, 0.0)))
    write(t, "inf_probe_velocity", local_model(v0=(0.0, 0.0, 1e300), probe=(0.0, 0.0, -1e-3)))
    write(t, "all_ones", b"\xff" * len(full))


# --- device_state: control, hapsim_msg_DeviceState fields ------------------------------------
def device_state(control=1, device=DEVICE, seq=10, scene=SCENE, time=0.01, p=(0.01, 0.02, 0.03),
                 q=(1.0, 0.0, 0.0, 0.0), v=(0.0, 0.1, 0.0), fingers=(0.1, 0.2, 0.3, 0.4, 0.0),
                 finger_count=4, buttons=1, healthy=1, force=(0.0, 0.0, 1.0),
                 finger_force=(0.5, 0.5, 0.0, 0.0, 0.0)):
    return (struct.pack("<BHQQd", control, device, seq, scene, time) +
            struct.pack("<3d4d3d5d", *p, *q, *v, *fingers) +
            struct.pack("<HIB", finger_count, buttons, healthy) +
            struct.pack("<3d5d", *force, *finger_force))


def device_state_seeds():
    t = "device_state"
    full = device_state()
    half = math.sqrt(0.5)
    write(t, "empty", b"")
    write(t, "short", full[:20])
    write(t, "valid", full)
    write(t, "valid_rotated", device_state(q=(half, 0.0, half, 0.0)))
    write(t, "drifted_quaternion", device_state(q=(1.0004, 0.0, 0.0, 0.0)))
    write(t, "zero_quaternion", device_state(q=(0.0, 0.0, 0.0, 0.0)))
    write(t, "nan_position", device_state(p=(NAN, 0.0, 0.0)))
    write(t, "inf_velocity", device_state(v=(0.0, -INF, 0.0)))
    write(t, "huge_position", device_state(p=(1e308, 0.0, 0.0)))
    write(t, "too_many_fingers", device_state(finger_count=9))
    write(t, "nan_finger_force", device_state(finger_force=(0.0, 0.0, 0.0, 0.0, NAN)))
    write(t, "huge_rendered_force", device_state(force=(0.0, 0.0, 5e3)))
    write(t, "other_device", device_state(control=0, device=4))
    write(t, "all_ones", b"\xff" * len(full))


# --- command: control, hapsim_msg_Command fields -----------------------------------------------
def command(control=1, issuer=7, seq=1, scene=SCENE, serve=0x5E5E5E5E5E5E5E5E, kind=4,
            material=1, fields=0b000101, values=(800.0, 0.01, 4.0, 1.0, 0.3, 0.2)):
    return (struct.pack("<BQQQQHIH", control, issuer, seq, scene, serve, kind, material, fields) +
            struct.pack("<6d", *values))


def command_seeds():
    t = "command"
    full = command()
    write(t, "empty", b"")
    write(t, "short", full[:20])
    write(t, "material", full)
    write(t, "pause", command(kind=1, fields=0))
    write(t, "resume", command(kind=2, fields=0))
    write(t, "reset", command(kind=3, fields=0))
    write(t, "unknown_kind", command(kind=9))
    write(t, "unknown_field", command(fields=0b1000000))
    write(t, "no_field", command(fields=0))
    write(t, "material_out_of_range", command(material=4))
    write(t, "nan_stiffness", command(values=(NAN, 0.01, 4.0, 1.0, 0.3, 0.2)))
    write(t, "negative_force", command(values=(800.0, 0.01, -4.0, 1.0, 0.3, 0.2)))
    write(t, "huge_stiffness", command(values=(1e300, 0.01, 4.0, 1.0, 0.3, 0.2)))
    write(t, "nan_unset_field", command(fields=0b000001, values=(800.0, NAN, INF, NAN, NAN, NAN)))
    write(t, "other_scene", command(control=0, scene=1))
    write(t, "other_serve", command(control=0, serve=1))
    write(t, "all_ones", b"\xff" * len(full))


# --- view_state: control, hapsim_msg_ViewState fields, then the sequences ---------------------
IDENTITY = (1.0, 0.0, 0.0, 0.0)
# A flat hand, fingers slightly bent: finger f's abduction, MCP, PIP.
HAND = (0.0, 0.3, 0.2) * 5


def view_state(control=0b11, scene=SCENE, time=1.5, tool_count=4, hand_p=(0.0, 0.1, 0.05),
               hand_q=IDENTITY, hand=HAND, bodies=(), deflection=(), offsets=(), contacts=(),
               tool_p=(0.0, 0.09, 0.03)):
    tool = struct.pack("<3d3d3ddi", *tool_p, *tool_p, 0.0, 0.0, 1.0, 1.0, 1)
    out = (struct.pack("<BQQQdBB", control, scene, 5, 1500, time, 0, 0) +
           struct.pack("<3d4d3d", 0.0, 0.1, 0.05, *IDENTITY, 0.0, 0.0, 1.0) +
           struct.pack("<H", tool_count) + tool * 5 +
           struct.pack("<3d4d15d", *hand_p, *hand_q, *hand))
    out += struct.pack("<H", len(bodies)) + b"".join(struct.pack("<3d4d", *p, *q) for p, q in bodies)
    out += struct.pack("<H", len(deflection)) + b"".join(struct.pack("<f", d) for d in deflection)
    out += struct.pack("<H", len(offsets)) + b"".join(
        struct.pack("<II3f", s, v, *o) for s, v, o in offsets)
    out += struct.pack("<H", len(contacts)) + b"".join(
        struct.pack("<iii3d3dddB", t, b, s, *p, *n, depth, f, 0)
        for t, b, s, p, n, depth, f in contacts)
    return out


def view_state_seeds():
    t = "view_state"
    contact = (1, 0, 3, (0.0, 0.09, 0.03), (0.0, 1.0, 0.0), 0.002, 1.5)
    full = view_state(offsets=((0, 10, (0.0, -0.001, 0.0)), (3, 5, (0.0, -0.002, 0.0))),
                      contacts=(contact,))
    write(t, "empty", b"")
    write(t, "short", full[:40])
    write(t, "valid_dented", full)
    write(t, "valid_at_rest", view_state())
    write(t, "other_scene", view_state(control=0b10, scene=1))
    write(t, "nan_hand_angle", view_state(hand=(NAN,) + HAND[1:]))
    write(t, "hand_not_a_rotation", view_state(hand_q=(2.0, 0.0, 0.0, 0.0)))
    write(t, "inf_deflection", view_state(deflection=(INF,)))
    write(t, "body_not_a_rotation", view_state(bodies=(((0, 0, 0), (0, 0, 0, 0)),)))
    write(t, "offset_out_of_range", view_state(offsets=((0, 1 << 30, (0.0, 0.0, 0.0)),)))
    write(t, "offset_nan", view_state(offsets=((0, 1, (NAN, 0.0, 0.0)),)))
    write(t, "contact_unknown_segment", view_state(contacts=((1, 0, 999) + contact[3:],)))
    write(t, "contact_negative_tool", view_state(contacts=((-1,) + contact[1:],)))
    write(t, "too_many_tools", view_state(control=0b10, tool_count=9))
    write(t, "all_ones", b"\xff" * len(full))


if __name__ == "__main__":
    # Only the packet targets' folders: the file targets' seeds (scene, mesh, ...) are the
    # shipped files and the hand-made hostile inputs, kept in the corpus as they are.
    packet_targets = ("legacy_packet", "local_model", "device_state", "command", "view_state")
    for target in packet_targets:
        if (CORPUS / target).exists():
            shutil.rmtree(CORPUS / target)
    legacy_seeds()
    local_model_seeds()
    device_state_seeds()
    command_seeds()
    view_state_seeds()
    for folder in sorted(CORPUS.iterdir()):
        print(f"{folder.relative_to(HERE.parent)}: {len(list(folder.iterdir()))} seeds")
