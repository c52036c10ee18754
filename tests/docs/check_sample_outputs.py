#!/usr/bin/env python3
"""The sample outputs of the docs, run and compared (ctest docs.sample_outputs).

A sample output in a doc sits between two markers:

    <!-- sample output: checked by the ctest docs.sample_outputs -->
    ```
    $ sinew-editor bake ../shared/content/cal3d/cally/cally.cfg -o /tmp/pk/cally.pack --threads 2
    baking ...
    ```
    <!-- end of sample output -->

Each `$ ` line is a command, run from the repository root with
`sinew-editor` and `sinew-demo` replaced by the built programs and `/tmp/pk/`
by a fresh folder of the build (so `/tmp/pk/` is shared by the commands of
all blocks, in document order); the lines after it, up to the next `$ ` line
or the fence, are its standard output. The blocks of a doc run in order, the
docs in the order given. A `...` line stands for any lines (none included).

Numbers that vary from run to run and machine to machine are written as
"…" in the doc (the docs carry no timings): a number followed by " ms" (a
timing), the process's RSS, the bake date, the demo's per-phase
milliseconds and frame rates (VARYING below). The program's output has
those replaced by "…", runs of spaces made one, and must then equal the
doc's line exactly: every other character and number (sizes, counts,
shares, areas) is checked, so the test fails as soon as a doc drifts from
what the programs print, or shows a timing.
"""

import argparse
import re
import shutil
import subprocess
import sys
from pathlib import Path

BEGIN = "<!-- sample output: checked by the ctest docs.sample_outputs -->"
END = "<!-- end of sample output -->"
NUMBER = r"-?[0-9]+(?:\.[0-9]+)?"
VARYING = [
    # Timings: "41 ms", "boxes 131 ms".
    (re.compile(NUMBER + r"(?= ms\b)"), "…"),
    # What the process happened to hold: "process peak RSS 129.1 MiB (127.3 MiB before the bake)".
    (re.compile(r"RSS " + NUMBER + r" MiB \(" + NUMBER + r" MiB before"), "RSS … MiB (… MiB before"),
    # The bake's date.
    (re.compile(r"baked [0-9]{4}-[0-9]{2}-[0-9]{2} [0-9]{2}:[0-9]{2}:[0-9]{2} UTC"), "baked … UTC"),
    # The demo's per-phase table: name, samples, then median, min and max ms.
    (re.compile(r"^([a-z][a-z ]*?) ([0-9]+) " + NUMBER + " " + NUMBER + " " + NUMBER + "$"), r"\1 \2 … … …"),
    # Frame rates: the demo's, and the scene report's "471.4 instead of 452.2 (+4%)".
    (re.compile(r"(phase medians\): )" + NUMBER), r"\1…"),
    (re.compile(r"(\): )" + NUMBER + " instead of " + NUMBER + r" \([+-]?[0-9]+%\)"), r"\1… instead of … (…)"),
]


def spaced(line):
    return re.sub(r" +", " ", line.rstrip())


def normalise(line):
    """The program's line as the doc writes it."""
    line = spaced(line)
    for pattern, replacement in VARYING:
        line = pattern.sub(replacement, line)
    return line


def blocks(doc_path):
    """(line number, [lines]) of every marked block, fences excluded."""
    text = Path(doc_path).read_text(encoding="utf-8").split("\n")
    found, i = [], 0
    while i < len(text):
        if text[i].strip() == BEGIN:
            start = i
            if i + 1 >= len(text) or not text[i + 1].startswith("```"):
                sys.exit(f"{doc_path}:{i + 2}: a sample output's code fence must follow its marker")
            j = i + 2
            while j < len(text) and not text[j].startswith("```"):
                j += 1
            if j + 1 >= len(text) or text[j + 1].strip() != END:
                sys.exit(f"{doc_path}:{j + 2}: the sample output's end marker must follow its closing fence")
            found.append((start + 1, text[i + 2 : j]))
            i = j + 2
        else:
            i += 1
    return found


def commands(block):
    """[(command, expected lines)] of one block."""
    out = []
    for line in block:
        if line.startswith("$ "):
            out.append((line[2:], []))
        elif not out:
            sys.exit(f"a sample output must start with a '$ ' command line, not: {line}")
        else:
            out[-1][1].append(line)
    return out


def matches(expected, actual):
    """Whether `actual` lines fit `expected`, where '...' matches any lines."""
    if not expected:
        return not actual
    if expected[0] == "...":
        return any(matches(expected[1:], actual[k:]) for k in range(len(actual) + 1))
    return bool(actual) and spaced(expected[0]) == normalise(actual[0]) and matches(expected[1:], actual[1:])


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--source-dir", required=True)
    parser.add_argument("--work-dir", required=True)
    parser.add_argument("--editor", required=True)
    parser.add_argument("--demo", required=True)
    parser.add_argument("docs", nargs="+")
    args = parser.parse_args()
    work = Path(args.work_dir)
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir(parents=True)
    failures, checked = 0, 0
    for doc in args.docs:
        doc_path = Path(args.source_dir) / doc
        for line_number, block in blocks(doc_path):
            for command, expected in commands(block):
                checked += 1
                real = command.replace("/tmp/pk/", f"{work}/")
                real = re.sub(r"^sinew-editor\b", args.editor, real)
                real = re.sub(r"^sinew-demo\b", args.demo, real)
                run = subprocess.run(real, shell=True, cwd=args.source_dir, capture_output=True, text=True)
                actual = run.stdout.replace(f"{work}/", "/tmp/pk/").rstrip("\n").split("\n")
                if run.returncode != 0 or not matches(expected, actual):
                    failures += 1
                    print(f"{doc}:{line_number}: '$ {command}' (exit {run.returncode}) no longer prints its sample "
                          "output. The doc shows:")
                    print("\n".join("  " + line for line in expected))
                    print("It prints, as the doc would write it (copy it into the doc if the change is right):")
                    print("\n".join("  " + normalise(line) for line in actual))
                    if run.stderr:
                        print("and on stderr:\n" + "\n".join("  " + line for line in run.stderr.splitlines()[-10:]))
                else:
                    print(f"{doc}:{line_number}: '$ {command}': as the doc shows")
    if checked == 0:
        sys.exit("no sample output found: the docs lost their markers")
    print(f"{checked - failures} of {checked} sample outputs as the docs show them")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
