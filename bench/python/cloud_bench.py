# SPDX-License-Identifier: MIT
"""Python binding benchmark: Plant.cloud(points=N) timed in Python against the same library
call from C (verdant_bench_cloud_call: vd_cloud_sample in a loop in one process, the plant grown
the same way), against the whole command line (`verdant cloud --stats`) and against Open3D's
TriangleMesh.sample_points_uniformly on the same tessellation, interleaved round by round in the
same run; best of R rounds (each C and Python round the best of 3 warm calls), wall and process
CPU seconds. Case: data/arabidopsis.lpy, seed 1, 100k and 1M points, 1 and 2 threads. Goal: the
Python call no slower than the C call + 5 %.

usage: PYTHONPATH=build/python /usr/bin/python3 bench/python/cloud_bench.py BUILD_DIR [--quick]
       [--reps R] [--csv PATH]
"""
import json
import os
import subprocess
import sys
import time


def main():
    args = sys.argv[1:]
    if not args:
        print(__doc__)
        return 2
    try:
        import verdant
    except ImportError as e:
        print(f"python bench skipped: the verdant package does not import ({e}); make python")
        return 0
    build = os.path.abspath(args[0])
    cli = os.path.join(build, "verdant")
    call = os.path.join(build, "verdant_bench_cloud_call")
    src = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    quick = "--quick" in args
    reps = 3 if quick else 7
    csv_path = os.path.join(src, "bench", "results", "python-cloud-2core.csv")
    for i, a in enumerate(args):
        if a == "--reps" and i + 1 < len(args):
            reps = int(args[i + 1])
        if a == "--csv" and i + 1 < len(args):
            csv_path = args[i + 1]
    plant_path = os.path.join(src, "data", "arabidopsis.lpy")
    plant = verdant.grow(plant_path, seed=1)
    try:
        import open3d as o3d
        o3d.utility.set_verbosity_level(o3d.utility.VerbosityLevel.Error)
        mesh = plant.to_open3d()
        print(f"peer: Open3D {o3d.__version__}, {len(mesh.triangles)} triangles")
    except ImportError:
        mesh = None
        print("Open3D peer skipped: python3-open3d is not installed (scripts/deps.sh --dev)")
    with open("/proc/loadavg") as f:
        load = f.read().split()[0]
    print(f"{os.cpu_count()} cores, load {load}; best of {reps} rounds")
    print(f"{'points':>9} {'threads':>7} {'python_s':>9} {'c_call_s':>9} {'py/c':>6} {'py_cpu':>7} "
          f"{'c_cpu':>7} {'cpu py/c':>8} {'cli_s':>7} {'open3d_s':>9} {'py/o3d':>7} {'goal':>6}")
    rows = []
    for n in (100000, 1000000):
        for threads in (1, 2):
            py = py_cpu = c_wall = c_cpu = cli_wall = o3d_s = 1e30
            plant.cloud(points=n, seed=1, threads=threads)  # warm the allocator, as C's first call
            for _ in range(reps):
                # C: vd_cloud_sample in a loop (best of 3 warm calls)
                r = subprocess.run([call, plant_path, "1", str(n), str(threads), "3"], check=True,
                                   capture_output=True, text=True)
                c = json.loads(r.stdout)
                c_wall, c_cpu = min(c_wall, c["wall"]), min(c_cpu, c["cpu"])
                # Python: the same call through the binding (best of 3)
                for _ in range(3):
                    c0, t0 = time.process_time(), time.perf_counter()
                    cl = plant.cloud(points=n, seed=1, threads=threads)
                    wall = time.perf_counter() - t0
                    py, py_cpu = min(py, wall), min(py_cpu, time.process_time() - c0)
                    del cl
                # the whole command (a fresh process: load, grow, sample, stats)
                t0 = time.perf_counter()
                subprocess.run([cli, "cloud", plant_path, "--seed", "1", "--points", str(n),
                                "--threads", str(threads), "--stats"], check=True, capture_output=True)
                cli_wall = min(cli_wall, time.perf_counter() - t0)
                if mesh is not None:
                    t0 = time.perf_counter()
                    mesh.sample_points_uniformly(number_of_points=n)
                    o3d_s = min(o3d_s, time.perf_counter() - t0)
            peer = o3d_s if mesh is not None else None
            met = py <= 1.05 * c_wall or py_cpu <= 1.05 * c_cpu
            print(f"{n:>9} {threads:>7} {py:>9.4f} {c_wall:>9.4f} {py / c_wall:>6.3f} {py_cpu:>7.4f} "
                  f"{c_cpu:>7.4f} {py_cpu / c_cpu:>8.3f} {cli_wall:>7.3f} "
                  f"{(f'{peer:.4f}' if peer else '-'):>9} {(f'{py / peer:.2f}' if peer else '-'):>7} "
                  f"{'met' if met else 'MISSED':>6}")
            rows += [
                ["python_cloud", "arabidopsis", n, threads, "python_call", py, "vd_cloud_sample from C", c_wall, py / c_wall],
                ["python_cloud", "arabidopsis", n, threads, "python_call_cpu", py_cpu, "vd_cloud_sample from C cpu", c_cpu, py_cpu / c_cpu],
                ["python_cloud", "arabidopsis", n, threads, "python_call", py, "verdant cloud --stats process", cli_wall, py / cli_wall],
            ]
            if peer:
                rows.append(["python_cloud", "arabidopsis", n, threads, "python_call", py,
                             "open3d.sample_points_uniformly", peer, py / peer])
    os.makedirs(os.path.dirname(csv_path), exist_ok=True)
    with open(csv_path, "w") as f:
        f.write(f"# {os.cpu_count()} cores, load {load} at the start; best of {reps}\n")
        f.write("bench,case,points,threads,what,seconds,peer,peer_seconds,ratio\n")
        for r in rows:
            f.write(",".join(f"{v:.6g}" if isinstance(v, float) else str(v) for v in r) + "\n")
    print(f"results: {csv_path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
