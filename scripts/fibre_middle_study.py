#!/usr/bin/env python3
"""Why the fibre layer model is too opaque near a bough's axis (docs/models.md, "Occluder profile").

One long paper bough (N 12, r 0.05, l 4.25, phi pi/8, dh 0.9), a line perpendicular to its axis
at offset g from it, its axial position uniform over a cone spacing. Prints the line's mean
transmittance three ways, each computed here from the geometry alone:

  model    the fibre layer model as cone_crossings.h has it: cone j's needles smeared over the
           band |h - rho cot(phi) - j dh| < dh / 2, sigma = coverage 2 r |d x a| per band-volume,
           each band stopping the line with probability min(1, n), bands independent;
  exact    the expectation over each cone's roll: the needles' azimuths at which a needle
           (radius r, as a capsule) meets the line, folded onto one needle period; the cone is
           missed where no needle's azimuth falls in them; cones independent;
  sides    the same with each cone's near and far halves rolled apart (what a cone's two
           crossings' correlation is worth).

With --simulate, also a Monte Carlo of explicit needles (random rolls), which `exact` should
match. The renders' needles (geometry method, 8 rolls) let through 0.022, 0.049-0.068 and 0.18
at g = 0.16, 0.23-0.3 and 0.69 cm.

    python3 scripts/fibre_middle_study.py [G ...] [--simulate]      (a few seconds per g)
"""
import argparse
import math
import random

N, r, l, phi, dh = 12, 0.05, 4.25, math.pi / 8, 0.9
R, reach = l * math.sin(phi), l * math.cos(phi)
period = 2 * math.pi / N
cot, sin_phi = 1 / math.tan(phi), math.sin(phi)


def model_T(x, g, steps=4000):
    if g >= R:
        return 1.0
    half = math.sqrt(R * R - g * g)
    T = 1.0
    for side in (-1, 1):  # the two monotone pieces of h - rho cot(phi) along the line
        bands = {}
        for i in range(steps):
            y = side * (i + 0.5) * half / steps
            rho = math.hypot(g, y)
            coverage = min(1.0, N * r / (math.pi * rho))
            along = sin_phi * y / rho  # d . a, a the needle direction there
            s = coverage * math.sqrt(max(0.0, 1 - along * along)) / (dh * sin_phi)
            j = math.floor((x - rho * cot) / dh + 0.5)
            bands[j] = bands.get(j, 0.0) + s * half / steps
        for n in bands.values():
            T *= 1 - min(1.0, n)
    return T


def distance(px, pz, ax, az, bx, bz):
    """From (px, pz) to the segment a-b in the plane across the line (the line's own distance)."""
    dx, dz = bx - ax, bz - az
    t = min(1.0, max(0.0, ((px - ax) * dx + (pz - az) * dz) / (dx * dx + dz * dz)))
    return math.hypot(ax + t * dx - px, az + t * dz - pz)


def exact_T(x, g, samples=1440, sides_apart=False):
    per = samples // N  # azimuth samples per needle period
    T = 1.0
    for k in range(math.floor((x - reach - r) / dh), math.floor((x + r) / dh) + 1):
        xj = k * dh
        groups = ((True, False) if sides_apart else (None,))
        for near in groups:
            hit = [False] * per
            for s in range(samples):
                psi = (s + 0.5) * 2 * math.pi / samples
                if near is not None and (math.sin(psi) < 0) != near:
                    continue
                if distance(x, g, xj, 0.0, xj + reach, R * math.cos(psi)) < r:
                    hit[s % per] = True
            T *= 1 - sum(hit) / per
    return T


def simulated_T(g, lines=20000, seed=1):
    rng = random.Random(seed)
    missed = 0
    for _ in range(lines):
        x = rng.uniform(0, dh)
        hit = False
        for k in range(math.floor((x - reach - r) / dh), math.floor((x + r) / dh) + 1):
            xj, roll = k * dh, rng.uniform(0, period)
            if any(distance(x, g, xj, 0.0, xj + reach, R * math.cos(roll + i * period)) < r
                   for i in range(N)):
                hit = True
                break
        missed += not hit
    return missed / lines


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("g", nargs="*", type=float, default=[0.164, 0.27, 0.5, 0.69, 1.0],
                        help="offsets from the axis, cm")
    parser.add_argument("--simulate", action="store_true", help="also simulate explicit needles")
    args = parser.parse_args()
    positions = 24
    for g in args.g:
        xs = [(i + 0.5) * dh / positions for i in range(positions)]
        line = "g %.3f cm: model %.4f  exact %.4f  sides %.4f" % (
            g, sum(model_T(x, g) for x in xs) / positions,
            sum(exact_T(x, g) for x in xs) / positions,
            sum(exact_T(x, g, sides_apart=True) for x in xs) / positions)
        if args.simulate:
            line += "  simulated needles %.4f" % simulated_T(g)
        print(line, flush=True)


if __name__ == "__main__":
    main()
