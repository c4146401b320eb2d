"""Reads the runs of bench/cycles/race.sh and prints, per scene and renderer, the relative RMSE of
each level against the renderer's own reference, the time to reach 2 %, 1 % and 0.5 %, and how
the two references agree. Usage: python3 analyse.py RUNS.tsv REF_SPP

Relative RMSE = RMSE over all pixels and channels / the reference's mean over the same. A
reference of N_ref spp has its own noise, which adds to the measured error in quadrature; with
error^2 = c/N for both (same renderer, same settings, another seed), the render's own error is
the measured one times sqrt(1 / (1 + N/N_ref)), which is what is reported ("corrected")."""
import csv
import math
import statistics
import sys
from collections import defaultdict

sys.path.insert(0, __file__.rsplit("/", 1)[0])
import pfm  # noqa: E402

runs_path, ref_spp = sys.argv[1], int(sys.argv[2])
rows = list(csv.DictReader(open(runs_path), delimiter="\t"))
by_key = defaultdict(list)
images, refs = {}, {}
for r in rows:
    if r["round"] == "ref":
        refs[(r["scene"], r["renderer"].split("-")[0])] = r["image"]
        continue
    key = (r["scene"], r["renderer"], int(r["spp"]))
    by_key[key].append((float(r["wall"]), float(r["render"]), float(r["cpu"])))
    images[key] = r["image"]

targets = (0.02, 0.01, 0.005)
scenes = sorted({k[0] for k in by_key})
summary = []
for scene in scenes:
    print(f"\n== {scene}")
    ref_data = {}
    for renderer in ("drt", "cycles"):
        _, _, ref_data[renderer] = pfm.read(refs[(scene, renderer)])
    a, b = ref_data["drt"], ref_data["cycles"]
    print("references: mean R G B, all — drt " +
          " ".join(f"{pfm.mean(a, c):.4f}" for c in range(3)) + f" {pfm.mean(a):.4f}; cycles " +
          " ".join(f"{pfm.mean(b, c):.4f}" for c in range(3)) + f" {pfm.mean(b):.4f}")
    print("  cycles/drt per channel: " +
          " ".join(f"{pfm.mean(b, c) / pfm.mean(a, c):.4f}" for c in range(3)) +
          f", all {pfm.mean(b) / pfm.mean(a):.4f}; relative RMSE between them "
          f"{pfm.relative_rmse(b, a):.4f}")
    curves = {}
    startups = {}  # per renderer: wall less start-up-excluded time, every run at every level
    drts = sorted({k[1] for k in by_key if k[0] == scene and k[1].startswith("drt")},
                  key=lambda n: (len(n), n))
    renderers = drts + ["cycles"]
    for renderer in renderers:
        ref = ref_data[renderer.split("-")[0]]
        points = []
        print(f"{renderer}: spp, relative RMSE measured, corrected, wall s (median, range), "
              "start-up excluded s (median, range), CPU s (median)")
        for spp in sorted(s for (sc, re, s) in by_key if sc == scene and re == renderer):
            _, _, img = pfm.read(images[(scene, renderer, spp)])
            measured = pfm.relative_rmse(img, ref)
            corrected = measured * math.sqrt(1 / (1 + spp / ref_spp))
            times = by_key[(scene, renderer, spp)]
            wall = [t[0] for t in times]
            render = [t[1] for t in times]
            cpu = [t[2] for t in times]
            points.append((spp, corrected, statistics.median(wall), statistics.median(render),
                           statistics.median(cpu)))
            startups.setdefault(renderer, []).extend(w - r for w, r in zip(wall, render))
            print(f"  {spp:6d} {measured:.5f} {corrected:.5f}  {statistics.median(wall):8.3f} "
                  f"({min(wall):.3f}-{max(wall):.3f})  {statistics.median(render):8.3f} "
                  f"({min(render):.3f}-{max(render):.3f})  {statistics.median(cpu):8.2f}")
        curves[renderer] = points

    def fit(points, column):
        """Least squares of time = a + b spp over the levels (medians over rounds): a is the
        fixed cost, b the cost of a sample a pixel."""
        xs = [p[0] for p in points]
        ys = [p[column] for p in points]
        mx, my = statistics.fmean(xs), statistics.fmean(ys)
        b = sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sum((x - mx) ** 2 for x in xs)
        return my - b * mx, b

    def reach(points, target, column):
        """Time at which the error reaches target: the spp between the bracketing levels by
        log-log interpolation of error against spp (beyond the levels, along the error of
        the nearest level times (spp/N)^-1/2: extrapolated, marked *), the time from fit()."""
        for lo, hi in zip(points, points[1:]):
            if lo[1] >= target >= hi[1]:
                f = math.log(lo[1] / target) / math.log(lo[1] / hi[1])
                spp = math.exp(math.log(lo[0]) + f * (math.log(hi[0]) - math.log(lo[0])))
                mark = " "
                break
        else:
            near = points[-1] if target < points[-1][1] else points[0]
            spp = near[0] * (near[1] / target) ** 2
            mark = "*"
        a, b = fit(points, column)
        return spp, a + b * spp, mark

    def startup(renderer):
        """The start-up a run adds to its start-up-excluded time: the median over every run.
        Start-up included, a renderer's time is its start-up-excluded line plus this, not a line
        fitted to the wall clocks: Blender's start-up varies by seconds from run to run, which
        would tilt such a line, and extrapolated far enough it would fall below the start-up-
        excluded one."""
        return statistics.median(startups[renderer])

    for renderer in renderers:
        pts = curves[renderer]
        slope = math.log(pts[-1][1] / pts[0][1]) / math.log(pts[-1][0] / pts[0][0])
        a_ex, b_ex = fit(pts, 3)
        print(f"{renderer}: slope of error against spp {slope:.3f}; fixed cost {a_ex:.3f} s "
              f"excluded, start-up {startup(renderer):.3f} s (median); per 1000 spp "
              f"{1000 * b_ex:.3f} s")

    print("time to reach (s): target; per renderer spp, start-up excluded, included, CPU; "
          "then Cycles' time / drt's (excluded, included, CPU)")
    for t in targets:
        line = f"  {t * 100:.1f} %"
        reached = {}
        for renderer in renderers:
            spp, ex, mark = reach(curves[renderer], t, 3)
            inc = ex + startup(renderer)
            _, cpu, _ = reach(curves[renderer], t, 4)
            reached[renderer] = (ex, inc, cpu)
            line += f" | {renderer} {spp:6.0f}{mark}spp {ex:7.2f} {inc:7.2f} {cpu:7.2f}"
        print(line)
        c = reached["cycles"]
        for renderer in renderers[:-1]:
            d = reached[renderer]
            # A time at or below 0 is a line fitted to clocks too coarse for the run (a tiny
            # --scale): no ratio is honest then.
            ratios = [f"{x / y:.2f}x" if x > 0 and y > 0 else "n/a" for x, y in zip(c, d)]
            print(f"      cycles / {renderer}: {ratios[0]} excluded, {ratios[1]} included, "
                  f"{ratios[2]} CPU")
