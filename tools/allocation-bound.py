#!/usr/bin/env python3
"""How far per-pixel sample counts could take a render to a target error below uniform rounds.

Reads the error image (--error-image, .pfm) of a render of N samples per pixel. Every figure
assumes each pixel's variance falls as n^(-2 alpha) from the render's: alpha 1/2 for
independent samples, larger where a stratified pattern's error falls faster. For each target
RMSE E it prints:
- the uniform count that reaches E, and the fewest samples per pixel on average that reach E
  when every pixel may take its own count (at least MIN): proportional to v^(1 / (2 alpha + 1))
  of the pixel's variance v (Lagrange), the pixels below MIN held there. An upper bound on what
  adaptive sampling could save: it knows every pixel's variance and pays for no rounds;
- with --top-up M, where the render falls short of 0.98 E: the share of pixels a top-up round
  of M samples on those pixels alone must cover to bring the image to 0.98 E, the pixels taken
  in order of their neighbours' largest variance (not their own: a pixel's own samples then do
  not decide whether it is topped up, so weighting its rounds does not bias it), and its cost
  in samples per image pixel.
See docs/accuracy.md, section 6, "What is left".

usage: tools/allocation-bound.py ERROR.pfm N [--targets 0.01,0.005] [--alphas 0.5,0.75] [--min 2]
                                 [--top-up M]
e.g.:  build/drt scenes/thesis/test2.xml --scale 0.5 --spp 64 --error-image e.pfm -o x.pfm
       tools/allocation-bound.py e.pfm 64
"""
import argparse
import array
import math
import sys

# A round meant as the last aims at this share of the target (kSpareShare, goal_render.h).
SPARE_SHARE = 0.98


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
    variances = [sum(values[3 * i + c] ** 2 for c in range(3)) / 3 for i in range(width * height)]
    return width, height, variances


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


def neighbours_largest(width, height, variances):
    """Each pixel's largest variance among its (up to) eight neighbours."""
    largest = []
    for y in range(height):
        for x in range(width):
            around = [variances[(y + dy) * width + x + dx]
                      for dy in (-1, 0, 1) for dx in (-1, 0, 1)
                      if (dx or dy) and 0 <= x + dx < width and 0 <= y + dy < height]
            largest.append(max(around, default=0.0))
    return largest


def top_up_share(variances, order, spp, target, alpha, added):
    """The share of pixels, taken in `order`, that `added` samples each bring to a mean variance
    of target^2; None where even every pixel does not."""
    left = sum(variances) - target * target * len(variances)
    ratio = (spp / added) ** (2 * alpha)  # the top-up's variance against the render's
    for taken, i in enumerate(order):
        if left <= 0:
            return taken / len(order)
        # Two independent estimates weighted by inverse variance: 1/v' = 1/v + 1/(v ratio).
        left -= variances[i] / (1 + ratio)
    return 1.0 if left <= 0 else None


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("error_image")
    parser.add_argument("spp", type=int, help="the samples per pixel of the render it came from")
    parser.add_argument("--targets", default="0.01,0.005")
    parser.add_argument("--alphas", default="0.5,0.75")
    parser.add_argument("--min", type=float, default=2, help="the fewest samples of any pixel")
    parser.add_argument("--top-up", type=int, help="samples of a top-up round on some pixels")
    args = parser.parse_args()
    if args.spp < 1 or (args.top_up is not None and args.top_up < 1):
        fail("the samples per pixel (N, --top-up) must be at least 1")
    width, height, variances = pixel_variances(args.error_image)
    rmse = math.sqrt(sum(variances) / len(variances))
    print(f"{args.error_image}: estimated RMSE {rmse:.5f} at {args.spp} spp")
    order = None
    if args.top_up is not None:
        around = neighbours_largest(width, height, variances)
        order = sorted(range(len(variances)), key=lambda i: -around[i])
    for target in map(float, args.targets.split(",")):
        for alpha in map(float, args.alphas.split(",")):
            uniform = args.spp * (rmse / target) ** (1 / alpha)
            per_pixel = fewest_samples(variances, args.spp, target, alpha, args.min)
            print(f"E {target} alpha {alpha}: uniform {uniform:.1f} spp, per pixel {per_pixel:.1f} "
                  f"spp on average ({per_pixel / uniform:.2f} of uniform)")
            goal = SPARE_SHARE * target
            if order is None or rmse <= goal:
                continue
            share = top_up_share(variances, order, args.spp, goal, alpha, args.top_up)
            if share is None:
                print(f"  a top-up of {args.top_up} spp on every pixel does not reach 0.98 E")
            else:
                print(f"  a top-up of {args.top_up} spp to 0.98 E: on {100 * share:.1f} % of the "
                      f"pixels, {args.top_up * share:.2f} samples per image pixel")


if __name__ == "__main__":
    main()
