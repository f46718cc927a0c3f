"""The Python module's two targets (docs/benchmarks.md#python), side by side with the C++:

1. a Python-driven `World.step` on the knee against the C++ step of the same world and inputs
   (the mean cycle of `run()`'s session, timed inside C++): the ratio, and the overhead in µs;
2. a batched 100k-point closest-point query from Python (`Mesh.closest`) against
   `hapsim query` on the same mesh and points (its mean per-query time): the throughput ratio.

    PYTHONPATH=build/release/python python3 bench/python_bench.py [--hapsim build/release/apps/hapsim]
"""

import argparse
import json
import pathlib
import subprocess
import tempfile
import time

import numpy as np

import hapsim

ROOT = pathlib.Path(__file__).resolve().parents[1]


def step_overhead(scene, seconds, repeats):
    with tempfile.TemporaryDirectory() as tmp:
        rec = pathlib.Path(tmp) / "knee.rec"
        summary = hapsim.run(scene, duration=seconds, record=str(rec))
        recording = hapsim.read_recording(str(rec))
        inputs = [recording.input(i) for i in range(len(recording))]
        cpp_us, python_us = [], []
        for _ in range(repeats):
            # The C++ step: the session's own timed cycle (read, step, safety) on the recording.
            # Medians on both sides: the session times each cycle in C++; here each Python call.
            cpp_us.append(hapsim.replay(scene, rec)["step_us"]["p50"])
            world = hapsim.World(scene)
            step = world.step
            clock = time.perf_counter_ns
            each_ns = np.empty(len(inputs))
            for i, inp in enumerate(inputs):
                t0 = clock()
                step(inp)
                each_ns[i] = clock() - t0
            python_us.append(float(np.median(each_ns)) / 1e3)
    cpp, py = min(cpp_us), min(python_us)
    return {"steps": summary["steps"], "cpp_step_us": cpp, "python_step_us": py,
            "overhead_us": py - cpp, "ratio": py / cpp}


def closest_throughput(hapsim_bin, mesh_spec, n, repeats):
    # A slow spiral walk around the 50 mm bumpy sphere, 44-56 mm from its centre: consecutive
    # points close together, as a probe's are (both sides use the previous answer as a hint).
    s = np.linspace(0.0, 1.0, n)
    theta = np.arccos(1.0 - 2.0 * s)
    phi = 400.0 * np.pi * s
    r = 0.05 + 0.006 * np.sin(2.0 * np.pi * 37.0 * s)
    points = np.stack([r * np.sin(theta) * np.cos(phi), r * np.sin(theta) * np.sin(phi),
                       r * np.cos(theta)], axis=1)
    mesh = hapsim.load_mesh(mesh_spec)
    mesh.closest(points[:10])  # build the BVH outside the timing
    python_s = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        mesh.closest(points)
        python_s.append(time.perf_counter() - t0)
    with tempfile.TemporaryDirectory() as tmp:
        csv = pathlib.Path(tmp) / "points.csv"
        np.savetxt(csv, points, delimiter=",", fmt="%.17g")
        cpp_ns = []
        for _ in range(repeats):
            out = pathlib.Path(tmp) / "q.json"
            subprocess.run([hapsim_bin, "query", mesh_spec, "--points", str(csv), "--out",
                            "/dev/null", "--json", str(out)], check=True, capture_output=True)
            cpp_ns.append(json.loads(out.read_text())["mean_ns"])
    python_qps = n / min(python_s)
    cpp_qps = 1e9 / min(cpp_ns)
    return {"points": n, "python_queries_per_s": python_qps, "cpp_queries_per_s": cpp_qps,
            "python_over_cpp": python_qps / cpp_qps}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--hapsim", default=str(ROOT / "build" / "release" / "apps" / "hapsim"))
    parser.add_argument("--scene", default=str(ROOT / "scenes" / "knee_paper.json"))
    parser.add_argument("--seconds", type=float, default=5.0)
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    step = step_overhead(args.scene, args.seconds, args.repeats)
    print(f"step on {pathlib.Path(args.scene).name} ({step['steps']} steps, best of "
          f"{args.repeats}, median step): C++ {step['cpp_step_us']:.2f} us, Python-driven "
          f"{step['python_step_us']:.2f} us: ratio {step['ratio']:.2f}, overhead "
          f"{step['overhead_us']:.2f} us per step")
    q = closest_throughput(args.hapsim, "builtin:bumpy-sphere", 100_000, args.repeats)
    print(f"closest, 100k points on builtin:bumpy-sphere (best of {args.repeats}): Python "
          f"{q['python_queries_per_s'] / 1e6:.2f} M/s, hapsim query {q['cpp_queries_per_s'] / 1e6:.2f}"
          f" M/s: {100.0 * (q['python_over_cpp'] - 1.0):+.1f} %")


if __name__ == "__main__":
    main()
