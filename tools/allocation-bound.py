#!/usr/bin/env python3
"""How far per-pixel sample counts could take a render below the cheapest uniform count.

Reads the error image (--error-image, .pfm) of a render of N samples per pixel and, for each
target RMSE E, prints the uniform count that reaches E and the fewest samples per pixel on
average that reach E when every pixel may take its own count (at least MIN). Both assume each
pixel's variance falls as n^(-2 alpha) from the render's: alpha 1/2 for independent samples,
larger where a stratified pattern's error falls faster. The per-pixel counts that spend the
fewest samples for a given mean variance are proportional to v^(1 / (2 alpha + 1)) (Lagrange),
the pixels below MIN held there. An upper bound on what adaptive sampling within the rounds of
--target-error could save (docs/accuracy.md, section 6, "What is left"): it knows every pixel's
variance exactly and pays no rounds.

usage: tools/allocation-bound.py ERROR.pfm N [--targets 0.01,0.005] [--alphas 0.5,0.75] [--min 2]
e.g.:  build/drt scenes/thesis/test2.xml --scale 0.5 --spp 64 --error-image e.pfm -o x.pfm
       tools/allocation-bound.py e.pfm 64
"""
import argparse
import array
import math
import sys


def fail(message):
    print(f"allocation-bound: {message}", file=sys.stderr)
    sys.exit(2)


def pixel_variances(path):
    """Each pixel's variance of the mean at the render's count: the mean of its channels' squares."""
    try:
        with open(path, "rb") as f:
            if f.readline().strip() != b"PF":
                fail(f"{path}: not a colour PFM")
            width, height = map(int, f.readline().split())
            scale = float(f.readline())
            data = f.read()
    except (OSError, ValueError) as error:
        fail(f"{path}: {error}")
    if len(data) != 12 * width * height:
        fail(f"{path}: {len(data)} bytes of pixels where {12 * width * height} were expected")
    values = array.array("f")
    values.frombytes(data)
    if scale > 0:
        values.byteswap()
    return [sum(values[3 * i + c] ** 2 for c in range(3)) / 3 for i in range(width * height)]


def fewest_samples(variances, spp, target, alpha, least):
    """The mean count of the per-pixel allocation whose mean variance is target^2."""
    shares = [v ** (1 / (2 * alpha + 1)) for v in variances]

    def spend(scale):
        counts = [max(least, scale * s) for s in shares]
        mean_variance = sum(v * (spp / n) ** (2 * alpha) for v, n in zip(variances, counts))
        return mean_variance / len(variances), sum(counts) / len(counts)

    low, high = 1e-6, 1e9
    for _ in range(80):
        middle = math.sqrt(low * high)
        low, high = (middle, high) if spend(middle)[0] > target * target else (low, middle)
    return spend(high)[1]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("error_image")
    parser.add_argument("spp", type=int, help="the samples per pixel of the render it came from")
    parser.add_argument("--targets", default="0.01,0.005")
    parser.add_argument("--alphas", default="0.5,0.75")
    parser.add_argument("--min", type=float, default=2, help="the fewest samples of any pixel")
    args = parser.parse_args()
    variances = pixel_variances(args.error_image)
    rmse = math.sqrt(sum(variances) / len(variances))
    print(f"{args.error_image}: estimated RMSE {rmse:.5f} at {args.spp} spp")
    for target in map(float, args.targets.split(",")):
        for alpha in map(float, args.alphas.split(",")):
            uniform = args.spp * (rmse / target) ** (1 / alpha)
            per_pixel = fewest_samples(variances, args.spp, target, alpha, args.min)
            print(f"E {target} alpha {alpha}: uniform {uniform:.1f} spp, per pixel {per_pixel:.1f} "
                  f"spp on average ({per_pixel / uniform:.2f} of uniform)")


if __name__ == "__main__":
    main()
