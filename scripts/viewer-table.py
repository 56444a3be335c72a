#!/usr/bin/env python3
"""The viewer's frame rates as a README table, from experiments/results/viewer_fps.json (written by
scripts/bench-viewer.sh). --readme rewrites the table between <!-- viewer-speed:begin --> and
<!-- viewer-speed:end --> in README.md; without it the table is printed."""
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from readme_blocks import write_blocks  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
LABELS = {
    "jello-rk4-shaded": "jello.w, rk4, shaded",
    "jello-rk4-wireframe": "jello.w, rk4, wireframe",
    "cube16-cvode-shaded": "cube16.w, cvode, shaded",
    "cube16-rk4-shaded": "cube16.w, rk4, shaded (the viewer's default: its loops on one CPU)",
    "cube16-rk4-shaded-2threads": "cube16.w, rk4, shaded, `JELLO_THREADS=2`",
}


def table():
    with open(os.path.join(ROOT, "experiments/results/viewer_fps.json")) as f:
        data = json.load(f)
    lines = ["| scene | frames/s drawn | simulated s per wall s | frames | multisampling | panel |",
             "|---|---:|---:|---:|---:|---|"]
    renderer = ""
    for name, label in LABELS.items():
        r = data["runs"][name]
        renderer = r["renderer"]
        lag = " (lagging)" if r["lagging"] else ""
        lines.append(f"| {label} | {r['fps']:.0f} | {r['sim_rate']:.3g}{lag} | {r['frames']} | "
                     f"{r['samples']}x | {r['panel']} |")
    lines.append("")
    lines.append(f"{r['width']}x{r['height']} under Xvfb with {renderer}; commit {data['commit']}; "
                 "from `experiments/results/viewer_fps.json`.")
    return "\n".join(lines)


def main():
    text = table()
    if "--readme" not in sys.argv[1:]:
        print(text)
        return
    write_blocks({"viewer-speed": text})


if __name__ == "__main__":
    main()
