#!/usr/bin/env python3
"""The docs are references: no measured figures and no work history in prose
(ctest docs.prose and docs.prose_self_test).

Measurements live in docs/BENCHMARKS.md and the README's headline table,
both written by `sinew-bench report`; history lives in git. This scans
README.md and docs/*.md, less docs/BENCHMARKS.md and the blocks the report
and the sample-output test own:

    <!-- headline table: ... -->       ...  <!-- end of headline table -->
    <!-- sample output: ... -->        ...  <!-- end of sample output -->

and fails, naming file, line and match, on:

- a commit hash: 7 to 40 hex digits, at least one a letter and one a digit;
- a work-history reference: "stop 44", "issue 49", "session 3", "earlier
  sessions", a date such as 2026-11-22;
- a measured figure: a number followed by "% faster", "× slower", "times
  faster", "times larger", "fps", "ms", "ms a frame", "speed-up of N", or
  a duration "about N s" or "took N s".

`--self-test` runs the patterns over sentences the docs once carried (each
must be caught) and over reference sentences the docs carry today (none may
be).
"""

import argparse
import re
import sys
from pathlib import Path

NUMBER = r"\d[\d,]*(?:\.\d+)?"
RANGE = NUMBER + r"(?:\s*[–-]\s*" + NUMBER + r")?"
PATTERNS = [
    ("commit hash", re.compile(r"\b(?=[0-9a-f]*[a-f])(?=[0-9a-f]*[0-9])[0-9a-f]{7,40}\b")),
    ("work history", re.compile(r"\b(?:stops?|issues?|sessions?)\s*#?\d+", re.IGNORECASE)),
    ("work history", re.compile(r"\b(?:this|earlier|previous|last|other)\s+sessions?\b", re.IGNORECASE)),
    ("dated figure", re.compile(r"\b20\d\d-\d\d-\d\d\b")),
    ("measured figure", re.compile(
        RANGE + r"\s*(?:%|×|x|times)\s+(?:faster|slower|larger|smaller|as fast|the speed)\b", re.IGNORECASE)),
    ("measured figure", re.compile(RANGE + r"\s*(?:fps|frames? a second|ms)\b")),
    ("measured figure", re.compile(r"\b(?:about|took|takes)\s+" + RANGE + r"\s*(?:s|seconds)\b")),
    ("measured figure", re.compile(r"\bspeed-?ups?\s+(?:of\s+)?" + NUMBER, re.IGNORECASE)),
]

# Blocks owned by generators and by docs.sample_outputs: left unscanned.
OWNED = [
    ("<!-- headline table", "<!-- end of headline table -->"),
    ("<!-- sample output", "<!-- end of sample output -->"),
]

# Sentences that once stood in the docs: each must be caught.
CAUGHT = [
    "16 clusters make Cally 15% faster a frame at 213,888 and 855,552 triangles "
    "and its pack 3.6 times larger at 855,552",
    "The BVHs trace as fast on the small models and 10–20% faster from 53,472 triangles on",
    "the demo runs at about 3 fps against the issue's 30 fps target",
    "Sinew is 1.70× slower than Embree at 855,552 triangles",
    "Cally at 9.9 ms a frame",
    "a speed-up of 1.6 on Cally",
    "as measured at 8c97c31 (stop 44/46/48)",
    "Last full runs (2026-11-22, commits 1cd3ad5–2ce8d01)",
    "the one-core work of issue 49",
    "Earlier sessions' packs and character packs: no findings.",
    "a 400,000-node chain now imports in about 2.7 s",
    "It takes about 28 s.",
]

# Reference sentences the docs carry: none may be caught.
PASSED = [
    "The BVH lists each triangle once and traces at least as fast as the paper's kd-tree",
    "default 16 from 25,000 triangles, else 0 (none, the paper's structure)",
    "`--light` may be given up to 8 times (the renderer's limit)",
    "every clip sampled every 1/30 s may last at most 600 s",
    "a 4×2-pixel block, or its 8×8-, 16×16- or 32×16-pixel region",
    "the fps (1000 / the sum of the medians)",
    "tinygltf keeps ids in `int`, so 4294967297 would read as 1",
    "`render` and the demo share `demo_session.h` and `DemoSession`",
    "`frame.ppm` must differ from the unpicked one",
    "Cally merges 17 of 37 bones",
    "Each level halves the one above (sides rounded down, never below 1)",
    "`./sinew fuzz 10`: every fuzzer for 10 s",
]


def prose_lines(text):
    """(line number, line) outside the owned blocks."""
    inside = None
    for number, line in enumerate(text.splitlines(), 1):
        if inside is None:
            for begin, end in OWNED:
                if line.lstrip().startswith(begin):
                    inside = end
                    break
            else:
                yield number, line
        elif line.strip() == inside:
            inside = None


def findings(line):
    for what, pattern in PATTERNS:
        for match in pattern.finditer(line):
            yield what, match.group(0)


def scan(root):
    docs = [root / "README.md"] + sorted(p for p in (root / "docs").glob("*.md") if p.name != "BENCHMARKS.md")
    bad = 0
    for doc in docs:
        for number, line in prose_lines(doc.read_text(encoding="utf-8")):
            for what, text in findings(line):
                print(f"{doc.relative_to(root)}:{number}: {what}: \"{text}\"")
                bad += 1
    if bad:
        print(f"{bad} finding(s). Measured figures belong in docs/BENCHMARKS.md (sinew-bench report): "
              "say what the code does and why, and name the report's section; history belongs in git.")
        return 1
    print(f"{len(docs)} docs: no measured figures or work history in prose")
    return 0


def self_test():
    failures = 0
    for sentence in CAUGHT:
        if not any(findings(sentence)):
            print(f"not caught: {sentence}")
            failures += 1
    for sentence in PASSED:
        for what, text in findings(sentence):
            print(f"caught by mistake ({what}, \"{text}\"): {sentence}")
            failures += 1
    blocks = "\n".join([
        "kept 1", "<!-- sample output: x -->", "9.9 ms a frame", "<!-- end of sample output -->",
        "kept 2", "<!-- headline table: y -->", "| 1.60× faster |", "<!-- end of headline table -->", "kept 3"])
    kept = [line for _, line in prose_lines(blocks)]
    if kept != ["kept 1", "kept 2", "kept 3"]:
        print(f"owned blocks not skipped: {kept}")
        failures += 1
    print("self-test " + ("failed" if failures else "passed"))
    return 1 if failures else 0


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("root", nargs="?", type=Path, help="the repository root")
    parser.add_argument("--self-test", action="store_true")
    args = parser.parse_args()
    if args.self_test:
        return self_test()
    if args.root is None:
        parser.error("the repository root is required")
    return scan(args.root)


if __name__ == "__main__":
    sys.exit(main())
