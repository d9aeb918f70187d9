#!/usr/bin/env python3
"""The default bake as a user runs it, timed: `skybake bake SCENE --force`
REPEAT times into a temporary pack; prints the median wall time of the whole
bake (process start to exit) and each product's median GPU and bake times.
The first bake also fills the driver's shader cache and is not counted.
Usage: bench_bake.py SKYBAKE SCENE [REPEAT] (meson test --benchmark; scripts/skybake-dev bench)."""
import json
import statistics
import subprocess
import sys
import tempfile
import time


def bake(skybake, scene, out):
    start = time.monotonic()
    run = subprocess.run([skybake, "bake", scene, "-o", out, "--force", "--json", "-q"],
                         capture_output=True, text=True)
    wall = time.monotonic() - start
    if run.returncode != 0:
        sys.exit(f"bench_bake: {skybake} bake {scene} failed ({run.returncode}):\n{run.stderr}")
    return wall, json.loads(run.stdout)


def main():
    if len(sys.argv) < 3:
        sys.exit("usage: bench_bake.py SKYBAKE SCENE [REPEAT]")
    skybake, scene = sys.argv[1], sys.argv[2]
    repeat = int(sys.argv[3]) if len(sys.argv) > 3 else 3
    with tempfile.TemporaryDirectory(prefix="skybake-bench-") as tmp:
        bake(skybake, scene, f"{tmp}/pack")
        runs = [bake(skybake, scene, f"{tmp}/pack") for _ in range(repeat)]
    summary = runs[0][1]
    print(f"default bake of {scene} on {summary['device']}: median of {repeat} (after one warm-up bake)")
    print(f"  {'product':<20} {'gpu ms':>10} {'bake ms':>10}")
    for i, artifact in enumerate(summary["artifacts"]):
        gpu = statistics.median(r[1]["artifacts"][i]["gpu_ms"] for r in runs)
        total = statistics.median(r[1]["artifacts"][i]["bake_ms"] for r in runs)
        print(f"  {artifact['name']:<20} {gpu:>10.1f} {total:>10.1f}")
    walls = sorted(r[0] for r in runs)
    print(f"  whole bake, wall: {statistics.median(walls):.2f} s (runs {', '.join(f'{w:.2f}' for w in walls)})")


if __name__ == "__main__":
    main()
