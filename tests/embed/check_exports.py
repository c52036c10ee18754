#!/usr/bin/env python3
"""Checks that a shared library exports only the public API: every defined
dynamic symbol is in namespace sinew::api, or is a weak instantiation of a
standard-library template that the API's std types bring along (vague
linkage: each user that instantiates it has its own copy). Anything else,
a sinew::rt, sinew::anim or other internal symbol, or a third-party one
(tbb::, glm::, nlohmann::), is a leak and fails.

  check_exports.py --nm NM LIBRARY   check the library (prints what leaks)
  check_exports.py --self-test       check the rules on made-up nm lines
"""
import re
import subprocess
import sys

WEAK = set("VvWwu")
INTERNAL_SINEW = re.compile(r"sinew::(?!api::)")
STD = re.compile(r"(^|[^\w:])(std|__gnu_cxx)::")


def leaks(lines):
    """(symbol, why) for each nm -D --defined-only -C line that leaks."""
    out = []
    for line in lines:
        parts = line.split(None, 2)
        if len(parts) < 3:
            continue
        kind, name = parts[1], parts[2]
        if INTERNAL_SINEW.search(name):
            out.append((name, "an internal sinew:: name"))
        elif "sinew::api::" in name:
            continue
        elif kind in WEAK and STD.search(name):
            continue
        elif kind in WEAK:
            out.append((name, "a weak symbol of neither the API nor the standard library"))
        else:
            out.append((name, f"a strong symbol ({kind}) outside sinew::api"))
    return out


def self_test():
    lines = [
        "0000000000012340 T sinew::api::World::render(sinew::api::Frame const&)",
        "0000000000012350 V typeinfo for std::bad_variant_access",
        "0000000000012360 W std::__cxx11::basic_string<char> __gnu_cxx::__to_xstring<>(int)",
        "0000000000012370 u std::__detail::__to_chars_10_impl<unsigned int>(char*)::__digits",
        "0000000000012380 V vtable for std::_Sp_counted_ptr_inplace<sinew::api::Character::Impl>",
        # leaks:
        "0000000000012390 T sinew::rt::Renderer::render()",
        "00000000000123a0 W std::vector<sinew::rt::Hit>::reserve(unsigned long)",
        "00000000000123b0 W tbb::detail::r1::execute()",
        "00000000000123c0 T some_c_function",
    ]
    found = [name for name, _ in leaks(lines)]
    expected = [lines[i].split(None, 2)[2] for i in (5, 6, 7, 8)]
    if found != expected:
        print("self-test: expected leaks", expected, "got", found)
        return 1
    print("self-test: the API and std instantiations pass, internal, third-party and C symbols are caught")
    return 0


def main(argv):
    if argv[1:] == ["--self-test"]:
        return self_test()
    if len(argv) != 4 or argv[1] != "--nm":
        print(__doc__.strip(), file=sys.stderr)
        return 2
    nm, library = argv[2], argv[3]
    result = subprocess.run([nm, "-D", "--defined-only", "-C", library], capture_output=True, text=True)
    if result.returncode != 0:
        print(f"{nm} failed on {library}: {result.stderr.strip()}", file=sys.stderr)
        return 2
    lines = result.stdout.splitlines()
    found = leaks(lines)
    for name, why in found:
        print(f"{library}: exports {name}: {why}")
    print(f"{len(lines)} exported symbols, {len(found)} outside the API")
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
