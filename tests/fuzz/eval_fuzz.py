#!/usr/bin/python3
"""`analytic eval` over random cases, moderate and extreme (magnitudes 5e-324 to 1.7e308,
aligned and opposite directions): every line is either answered with finite outputs in their
physical ranges or (extreme inputs only) refused with one line and status 2; never a crash,
NaN, infinity (null) or a value out of range. Usage: eval_fuzz.py ANALYTIC [CASES] [SEED]. Exits 1 on any finding."""
import json
import math
import random
import subprocess
import sys

analytic = sys.argv[1]
count = int(sys.argv[2]) if len(sys.argv) > 2 else 20000
rng = random.Random(int(sys.argv[3]) if len(sys.argv) > 3 else 1)
EXTREMES = [0.0, 5e-324, 1e-300, 1e-10, 1e10, 1e300, 1.7e308]


def vector(extreme):
    if extreme:
        v = [rng.choice([-1, 1]) * 10 ** rng.uniform(-300, 300) for _ in range(3)]
        if rng.random() < 0.3:
            v[rng.randrange(3)] = 0.0
    else:
        v = [rng.gauss(0, 1) for _ in range(3)]
        if rng.random() < 0.1:
            v = [0.0, 0.0, 1.0]
    return v if any(v) else [0.0, 0.0, 1.0]


def number(lo, hi, extreme, minimum=0.0, strict=False):
    """log-uniform in [lo, hi]; extreme: a magnitude from EXTREMES within the domain."""
    if extreme and rng.random() < 0.5:
        v = rng.choice(EXTREMES)
        if v > minimum or (v == minimum and not strict):
            return v
        return max(minimum * (1 + 1e-12), 5e-324) if strict else minimum
    return 10 ** rng.uniform(math.log10(lo), math.log10(hi))


def case(extreme):
    level = rng.choice(["needle", "cone", "bough"])
    c = {"level": level, "axis": vector(extreme), "L": vector(extreme), "V": vector(extreme)}
    r = rng.random()  # the hard cases of DESIGN.md: L = V, V or L along the axis, L = -V
    if r < 0.1:
        c["L"] = c["V"]
    elif r < 0.2:
        c["V"] = c["axis"]
    elif r < 0.3:
        c["L"] = c["axis"]
    elif r < 0.35:
        c["L"] = [-x for x in c["V"]]
    if level == "needle":
        c["exponent"] = number(0.01, 1e4, extreme, 0.0, True)
        if rng.random() < 0.5:
            c["radius"] = number(1e-4, 10, extreme)
            c["length"] = number(1e-3, 100, extreme)
            if rng.random() < 0.5:
                c["footprint_area"] = number(1e-6, 1e4, extreme)
        return c
    c["exponent"] = number(1.01, 1e4, extreme, 1.0, True)
    c["radius"] = number(1e-4, 1, extreme)
    c["length"] = number(1e-2, 50, extreme)
    c["aperture"] = rng.choice([0.0, 1e-300, math.pi / 2, rng.uniform(1e-6, math.pi / 2)])
    c["needles_per_cone"] = rng.choice([0.0, 1.0, number(1, 1000, extreme)])
    if level == "bough":
        c["cone_spacing"] = number(1e-3, 10, extreme, 0.0, True)
    elif rng.random() < 0.5:
        c["footprint_area"] = number(1e-6, 1e4, extreme)
    return c


UNIT = {"alpha", "A", "alpha_front", "alpha_rear", "alpha_exact", "alpha_front_exact",
        "alpha_rear_exact"}
SIGNED = {"cos_lv"}
cases = [case(i % 2 == 1) for i in range(count)]
findings, refused, answered, start = [], 0, 0, 0
CHUNK = 400  # lines a process: a refusal restarts on the rest of its chunk only
while start < len(cases):
    lines = "".join(json.dumps(c) + "\n" for c in cases[start:start + CHUNK])
    run = subprocess.run([analytic, "eval"], input=lines, capture_output=True, text=True,
                         timeout=600)
    outputs = [json.loads(l) for l in run.stdout.splitlines()]
    for c, o in zip(cases[start:], outputs):
        answered += 1
        for key, value in o.items():
            if value is None or (isinstance(value, float) and not math.isfinite(value)):
                findings.append(("not finite", key, c))
            elif isinstance(value, (int, float)) and not isinstance(value, bool):
                if value < 0 and key not in SIGNED:
                    findings.append(("negative", key, c))
                if key in UNIT and value > 1:
                    findings.append(("above 1", key, c))
    start += len(outputs)
    if run.returncode == 0:
        continue
    err = run.stderr.strip().splitlines()
    if run.returncode != 2 or len(err) != 1 or not err[0].startswith("analytic eval: line "):
        findings.append(("bad stop (status %d)" % run.returncode, run.stderr[-300:],
                         cases[start] if start < len(cases) else None))
        break
    refused += 1
    if start % 2 == 0:  # moderate inputs are always answered
        findings.append(("moderate case refused", err[0], cases[start]))
    start += 1  # the refused line
for what, key, c in findings[:20]:
    print("FINDING: %s: %s: %s" % (what, key, json.dumps(c)))
print("eval fuzz: %d cases, %d answered, %d refused, %d findings"
      % (count, answered, refused, len(findings)))
sys.exit(1 if findings else 0)
