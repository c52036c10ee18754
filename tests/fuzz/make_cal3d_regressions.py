#!/usr/bin/env python3
"""Writes the Cal3D regression inputs of corpus/cal3d_import/ as minimal,
hand-built files (no third-party bytes): each reproduces one finding of the
cal3d_import fuzzer (docs/ROBUSTNESS.md), behind the fuzzer's selector byte
(0 .csf, 1 .cmf, 2 .caf, 3 .xrf).

    python3 tests/fuzz/make_cal3d_regressions.py
"""
import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.join(HERE, "corpus", "cal3d_import")
VERSION = 700  # the file version of the test content (layout as in 910)


def cal_string(text, nul=True):
    data = text.encode() + (b"\0" if nul else b"")
    return struct.pack("<i", len(data)) + data


def bone(name, parent, children=(), nul=True):
    identity = struct.pack("<3f4f", 0, 0, 0, 0, 0, 0, 1)
    return (cal_string(name, nul) + identity + identity + struct.pack("<i", parent) +
            struct.pack("<i", len(children)) + b"".join(struct.pack("<i", c) for c in children))


def skeleton(*bones):
    return b"CSF\0" + struct.pack("<ii", VERSION, len(bones)) + b"".join(bones)


def animation(duration, tracks):
    body = b""
    for bone_id, keys in tracks:
        body += struct.pack("<ii", bone_id, len(keys))
        for time in keys:
            body += struct.pack("<f3f4f", time, 0, 0, 0, 0, 0, 0, 1)
    return b"CAF\0" + struct.pack("<ifi", VERSION, duration, len(tracks)) + body


def write(name, selector, data):
    with open(os.path.join(OUT, name), "wb") as f:
        f.write(bytes([selector]) + data)


def main():
    os.makedirs(OUT, exist_ok=True)
    # Cal3D read the name with strlen, past its buffer.
    write("crash-csf-name-without-nul.csf", 0, skeleton(bone("root", -1, nul=False)))
    # A parent id past the bones: CalCoreBone::calculateState dereferenced null.
    write("crash-csf-parent-out-of-range.csf", 0, skeleton(bone("root", -1, [1]), bone("child", 5)))
    # Cal3D failed on the second track and leaked the first.
    write("leak-caf-negative-bone.caf", 2, animation(1.0, [(0, [0.0, 1.0]), (-17, [0.0])]))
    # Cal3D's XML loader called strcasecmp on the missing MAGIC attribute.
    xrf = ('<HEADER VERSION="900" />\n<MATERIAL NUMMAPS="0">\n'
           "    <AMBIENT>0 0 0 0</AMBIENT>\n    <DIFFUSE>128 128 128 0</DIFFUSE>\n"
           "    <SPECULAR>0 0 0 0</SPECULAR>\n    <SHININESS>0</SHININESS>\n</MATERIAL>\n")
    write("crash-xrf-missing-magic.xrf", 3, xrf.encode())


if __name__ == "__main__":
    main()
