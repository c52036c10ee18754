#!/usr/bin/env python3
"""Checks every quoted #include of the project's sources against the layer
rules in layers.txt (beside this file). Prints each forbidden include as
FILE:LINE: includes HEADER (FOLDER may include only ...) and exits 1 if
there is any; exits 2 on a malformed rules file.

  check_includes.py ROOT            check the tree at ROOT
  check_includes.py --self-test     check that a forbidden include is caught
"""
import os
import re
import sys
import tempfile

SOURCE_SUFFIXES = (".h", ".hpp", ".cpp", ".cc", ".inl")
SKIPPED_DIRS = {"build", ".git", "out", "node_modules"}
INCLUDE = re.compile(r'^\s*#\s*include\s*"([^"]+)"')


def load_rules(path):
    allowed, exceptions = {}, set()
    with open(path, encoding="utf-8") as f:
        for number, raw in enumerate(f, 1):
            line = raw.split("#", 1)[0].strip()
            if not line:
                continue
            if line.startswith("except "):
                parts = line.split()
                if len(parts) != 3:
                    print(f"{path}:{number}: 'except FILE HEADER' expected, got {raw.strip()!r}", file=sys.stderr)
                    sys.exit(2)
                exceptions.add((parts[1], parts[2]))
                continue
            folder, sep, rest = line.partition(":")
            if not sep or not folder.endswith("/"):
                print(f"{path}:{number}: 'FOLDER/: ALLOWED/ ...' expected, got {raw.strip()!r}", file=sys.stderr)
                sys.exit(2)
            allowed[folder] = rest.split()
    return allowed, exceptions


def rule_for(path, allowed):
    matches = [folder for folder in allowed if path.startswith(folder)]
    return max(matches, key=len) if matches else None


def check(root, allowed, exceptions):
    problems, checked, used = [], 0, set()
    for top, dirs, files in os.walk(root):
        dirs[:] = sorted(d for d in dirs if d not in SKIPPED_DIRS)
        for name in sorted(files):
            if not name.endswith(SOURCE_SUFFIXES):
                continue
            full = os.path.join(top, name)
            path = os.path.relpath(full, root).replace(os.sep, "/")
            folder = rule_for(path, allowed)
            if folder is None:
                continue
            own = folder if folder != "include/sinew/" else "sinew/"
            with open(full, encoding="utf-8", errors="replace") as f:
                for number, text in enumerate(f, 1):
                    m = INCLUDE.match(text)
                    if not m:
                        continue
                    checked += 1
                    header = m.group(1)
                    if "/" not in header:
                        continue  # beside the file
                    if header.startswith(own) or any(header.startswith(a) for a in allowed[folder]):
                        continue
                    if (path, header) in exceptions:
                        used.add((path, header))
                        continue
                    may = " ".join([own] + allowed[folder])
                    problems.append(f"{path}:{number}: includes {header} ({folder} may include only {may})")
    # An exception that no longer happens goes from the rules, so the list
    # only shrinks.
    for path, header in sorted(exceptions - used):
        if os.path.exists(os.path.join(root, path)):
            problems.append(f"{path}: no longer includes {header}: remove its 'except' line from layers.txt")
    return problems, checked


def self_test(rules_path):
    allowed, exceptions = load_rules(rules_path)
    with tempfile.TemporaryDirectory() as root:
        def write(path, text):
            full = os.path.join(root, path)
            os.makedirs(os.path.dirname(full), exist_ok=True)
            with open(full, "w", encoding="utf-8") as f:
                f.write(text)
        write("runtime/core/a.h", '#include <vector>\n#include "runtime/core/b.h"\n#include "c.h"\n')
        write("raytrace/render/r.cpp", '#include "runtime/core/a.h"\n')
        problems, _ = check(root, allowed, exceptions)
        if problems:
            print("self-test: a clean tree was refused:", *problems, sep="\n  ")
            return 1
        write("raytrace/render/bad.cpp", '#include "runtime/core/a.h"\n  #  include "animation/clip.h"\n')
        write("runtime/core/worse.h", '#include "editor/import/model_loader.h"\n')
        problems, _ = check(root, allowed, exceptions)
        expected = {"raytrace/render/bad.cpp:2", "runtime/core/worse.h:1"}
        found = {p.split(": ", 1)[0] for p in problems}
        if found != expected:
            print("self-test: expected", sorted(expected), "got", problems)
            return 1
    print("self-test: forbidden includes are caught, allowed ones pass")
    return 0


def main(argv):
    rules_path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "layers.txt")
    if len(argv) == 2 and argv[1] == "--self-test":
        return self_test(rules_path)
    if len(argv) != 2:
        print(__doc__.strip(), file=sys.stderr)
        return 2
    allowed, exceptions = load_rules(rules_path)
    problems, checked = check(argv[1], allowed, exceptions)
    for p in problems:
        print(p)
    print(f"{checked} includes checked, {len(problems)} forbidden")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
