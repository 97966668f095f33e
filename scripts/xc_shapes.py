#!/usr/bin/env python3
"""xc_shapes.py - cross-check against POV-Ray 3.7.

Renders every example in the given scene directories (default: POV-Ray's
objects/, objects/quartic/, objects/csg/) at 160x120 with partray and with
povray, and prints, per scene, the mean absolute difference of the sRGB
images after a 4x4 box downsample (0..1 of white) and whether they agree
(<= 0.02). A scene counts as "supported" when partray renders it without
warnings that it skipped something the scene uses: an object it does not
render ("not rendered yet", "is skipped") or a warning located in the scene
file itself ("not supported", "ignored", "not available"); warnings from
declarations in POV-Ray's include files that the scene never uses do not
count. The summary line gives the fraction of supported scenes that agree.

Usage: scripts/xc_shapes.py [--partray PATH] [--out DIR] [--size WxH] [--jobs N] [DIR|FILE ...]
Only the Python 3 standard library is needed (PNG reading: scripts/pngread.py)."""
import argparse
import os
import re
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from pngread import mad4, read_png  # noqa: E402

SCENES = "/usr/share/povray-3.7/scenes"
INCLUDE = "/usr/share/povray-3.7/include"


SKIP_WORDS = re.compile(r"not rendered yet|is skipped|skipped")
SCENE_WORDS = re.compile(r"not supported|ignored|not available|not evaluated")


def classify(log, scene):
    """'' when the scene uses only supported features, else the first reason."""
    for line in log.splitlines():
        if ": warning:" not in line and ": error:" not in line:
            continue
        if ": error:" in line:
            return line.strip()
        if SKIP_WORDS.search(line):
            return line.strip()
        if line.startswith(scene) and SCENE_WORDS.search(line):
            return line.strip()
    return ""


def render(args, scene, out):
    base = os.path.splitext(os.path.basename(scene))[0]
    d = os.path.dirname(scene)
    w, h = args.size.split("x")
    ours, theirs = os.path.join(out, base + ".png"), os.path.join(out, base + "_pov.png")
    r = subprocess.run([args.partray, "render", scene, "-o", ours, "--size", args.size, "--threads", "1"], cwd=d,
                       capture_output=True, text=True, timeout=args.timeout)
    log = r.stdout + r.stderr
    if r.returncode != 0:
        return base, None, "partray exit %d: %s" % (r.returncode, log.strip().splitlines()[-1] if log.strip() else "")
    p = subprocess.run(["povray", "+I" + scene, "+O" + theirs, "+W" + w, "+H" + h, "-D", "-V", "+L" + INCLUDE,
                        "+L" + d, "Work_Threads=1"], cwd=d, capture_output=True, text=True, timeout=args.timeout)
    if p.returncode != 0 or not os.path.exists(theirs):
        return base, None, "povray failed"
    return base, mad4(read_png(ours), read_png(theirs)), classify(log, scene)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--partray", default=os.path.join(os.path.dirname(__file__), "..", "build", "partray"))
    ap.add_argument("--out", default="xc_shapes_out")
    ap.add_argument("--size", default="160x120")
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--timeout", type=int, default=600)
    ap.add_argument("--tol", type=float, default=0.02)
    ap.add_argument("paths", nargs="*")
    args = ap.parse_args()
    paths = args.paths or [os.path.join(SCENES, p) for p in ("objects", "objects/quartic", "objects/csg")]
    scenes = []
    for p in paths:
        if os.path.isdir(p):
            scenes += sorted(os.path.join(p, f) for f in os.listdir(p) if f.endswith(".pov"))
        else:
            scenes.append(p)
    os.makedirs(args.out, exist_ok=True)
    with ThreadPoolExecutor(max_workers=max(1, args.jobs)) as ex:
        results = list(ex.map(lambda s: render(args, s, args.out), scenes))
    sup = agree = 0
    for base, mad, why in results:
        if mad is None:
            print("%-14s  failed   %s" % (base, why))
            continue
        ok = mad <= args.tol
        if not why:
            sup += 1
            agree += ok
        print("%-14s  %.4f  %-8s %s" % (base, mad, "agree" if ok else "DIFFER", ("[unsupported: %s]" % why) if why else ""))
    print("supported scenes: %d of %d; agreeing: %d of %d (%.0f%%)" %
          (sup, len(results), agree, sup, 100.0 * agree / sup if sup else 0.0))
    return 0


if __name__ == "__main__":
    sys.exit(main())
