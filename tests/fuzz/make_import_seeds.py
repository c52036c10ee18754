#!/usr/bin/env python3
"""Writes the third-party seeds of the gltf_import and cal3d_import fuzzers.

    python3 tests/fuzz/make_import_seeds.py OUT_DIR [SHARED_DIR] [ASSIMP_MODELS_DIR]

writes OUT_DIR/gltf_import/ and OUT_DIR/cal3d_import/. The fuzz build runs it
at configure time into build/fuzz/seeds/ (tests/fuzz/CMakeLists.txt): the
seeds are derived from third-party files (../shared/content, Debian's
assimp-testmodels), which the project never copies into its own tree. The
committed corpus folders hold only the project's own inputs: regression
inputs of fixed findings and hand-written seeds.

Defaults: ../shared (next to the checkout) and /usr/share/assimp/models.
Seeds must be self-contained and small:
* glTF: external buffers are embedded as base64 data: URIs and images,
  textures and samplers are dropped (the fuzzer's scratch folder holds only
  the model, and the importer never decodes images); .glb files are rebuilt
  with only the bufferViews that accessors use. Files still over 300 KB are
  skipped. Broken and odd files (wrong JSON types, recursive nodes, indices
  out of range...) are kept as they are: they are the point.
* Cal3D: the selector byte of cal3d_import_fuzz.cpp, then the file.
Missing source files are skipped with a note, so a machine without the
shared content still gets the assimp seeds (and the committed ones).
"""
import base64
import json
import os
import struct
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
if len(sys.argv) < 2:
    sys.exit("usage: make_import_seeds.py OUT_DIR [SHARED_DIR] [ASSIMP_MODELS_DIR]")
OUT = sys.argv[1]
SHARED = sys.argv[2] if len(sys.argv) > 2 else os.path.join(HERE, "..", "..", "..", "shared")
ASSIMP = sys.argv[3] if len(sys.argv) > 3 else "/usr/share/assimp/models"
MAX_SEED = 300 * 1024


def drop_images(doc):
    for key in ("images", "textures", "samplers"):
        doc.pop(key, None)

    def scrub(node):
        if isinstance(node, dict):
            for k in [k for k in node if k.endswith("Texture")]:
                del node[k]
            for v in node.values():
                scrub(v)
        elif isinstance(node, list):
            for v in node:
                scrub(v)
    scrub(doc.get("materials", []))


def gltf_seed(path):
    with open(path, "rb") as f:
        raw = f.read()
    try:
        doc = json.loads(raw)
    except ValueError:
        return raw  # broken JSON: keep the bytes
    if not isinstance(doc, dict):
        return raw
    folder = os.path.dirname(path)
    for buf in doc.get("buffers", []) if isinstance(doc.get("buffers"), list) else []:
        uri = buf.get("uri") if isinstance(buf, dict) else None
        if isinstance(uri, str) and not uri.startswith("data:"):
            bin_path = os.path.join(folder, uri)
            if os.path.isfile(bin_path):
                with open(bin_path, "rb") as f:
                    buf["uri"] = "data:application/octet-stream;base64," + \
                        base64.b64encode(f.read()).decode()
    drop_images(doc)
    return json.dumps(doc, separators=(",", ":")).encode()


def glb_seed(path):
    with open(path, "rb") as f:
        raw = f.read()
    magic, version, _ = struct.unpack_from("<4sII", raw, 0)
    if magic != b"glTF" or version != 2:
        return raw
    json_len, json_type = struct.unpack_from("<II", raw, 12)
    doc = json.loads(raw[20:20 + json_len])
    bin_at = 20 + json_len
    bin_chunk = b""
    if bin_at + 8 <= len(raw):
        bin_len, _ = struct.unpack_from("<II", raw, bin_at)
        bin_chunk = raw[bin_at + 8:bin_at + 8 + bin_len]
    drop_images(doc)
    # Keep only the bufferViews accessors use, packed 4-aligned; renumber.
    used = sorted({a["bufferView"] for a in doc.get("accessors", []) if "bufferView" in a})
    new_bin = bytearray()
    remap = {}
    views = []
    for old in used:
        view = dict(doc["bufferViews"][old])
        data = bin_chunk[view.get("byteOffset", 0):view.get("byteOffset", 0) + view["byteLength"]]
        while len(new_bin) % 4:
            new_bin.append(0)
        view["byteOffset"] = len(new_bin)
        view["buffer"] = 0
        new_bin += data
        remap[old] = len(views)
        views.append(view)
    for a in doc.get("accessors", []):
        if "bufferView" in a:
            a["bufferView"] = remap[a["bufferView"]]
    doc["bufferViews"] = views
    while len(new_bin) % 4:
        new_bin.append(0)
    doc["buffers"] = [{"byteLength": len(new_bin)}]
    js = json.dumps(doc, separators=(",", ":")).encode()
    js += b" " * (-len(js) % 4)
    out = struct.pack("<4sII", b"glTF", 2, 12 + 8 + len(js) + 8 + len(new_bin))
    out += struct.pack("<I4s", len(js), b"JSON") + js
    out += struct.pack("<I4s", len(new_bin), b"BIN\0") + bytes(new_bin)
    return out


def present(path):
    if os.path.exists(path):
        return True
    print(f"make_import_seeds: skipped (missing) {path}")
    return False


def write(folder, name, data):
    if len(data) > MAX_SEED:
        print(f"skipped {name}: {len(data)} bytes")
        return
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, name), "wb") as f:
        f.write(data)


def main():
    gltf_out = os.path.join(OUT, "gltf_import")
    g2 = os.path.join(ASSIMP, "glTF2")
    gltf_files = [
        "BoxTextured-glTF/BoxTextured.gltf",
        "BoxTextured-glTF-Embedded/BoxTextured.gltf",
        "BoxTexcoords-glTF/boxTexcoords.gltf",
        "IncorrectVertexArrays/Cube.gltf",
        "IndexOutOfRange/IndexOutOfRange.gltf",
        "IndexOutOfRange/AllIndicesOutOfRange.gltf",
        "MissingBin/BoxTextured.gltf",
        "RecursiveNodes/RecursiveNodes.gltf",
        "SchemaFailures/sceneWrongType.gltf",
        "TestNoRootNode/NoScene.gltf",
        "TestNoRootNode/SceneWithoutNodes.gltf",
        "cameras/Cameras.gltf",
        "glTF-Asset-Generator/Mesh_PrimitiveMode/Mesh_PrimitiveMode_00.gltf",
        "glTF-Asset-Generator/Mesh_PrimitiveMode/Mesh_PrimitiveMode_13.gltf",
        "glTF-Sample-Models/AnimatedMorphCube-glTF/AnimatedMorphCube.gltf",
        "issue_3269/texcoord_crash.gltf",
        "simple_skin/simple_skin.gltf",
        "wrongTypes/badArray.gltf",
        "wrongTypes/badExtension.gltf",
        "wrongTypes/badNumber.gltf",
        "wrongTypes/badObject.gltf",
        "wrongTypes/badString.gltf",
        "wrongTypes/badUint.gltf",
    ]
    for rel in gltf_files:
        name = "assimp-" + rel.replace("/", "-").replace("glTF-Asset-Generator-Mesh_PrimitiveMode-", "")
        if present(os.path.join(g2, rel)):
            write(gltf_out, name, gltf_seed(os.path.join(g2, rel)))
    for rel in ["BoxTextured-glTF-Binary/BoxTextured.glb", "BoxBadNormals-glTF-Binary/BoxBadNormals.glb",
                "BoxWithInfinites-glTF-Binary/BoxWithInfinites.glb"]:
        if present(os.path.join(g2, rel)):
            write(gltf_out, "assimp-" + os.path.basename(rel), glb_seed(os.path.join(g2, rel)))
    cesium = os.path.join(SHARED, "content/gltf/CesiumMan/CesiumMan.glb")
    if present(cesium):
        write(gltf_out, "CesiumMan.glb", glb_seed(cesium))

    cal3d_out = os.path.join(OUT, "cal3d_import")
    selectors = {".csf": 0, ".cmf": 1, ".caf": 2, ".xrf": 3}
    for model, files in [("cally", ["cally.csf", "cally_neck.cmf", "cally_foot_left.cmf", "cally_idle.caf",
                                    "cally_skin.xrf", "cally_chest.xrf"]),
                         ("skeleton", ["skeleton.csf", "skeleton_neck.cmf", "skeleton_idle.caf",
                                       "skeleton_bone.xrf"])]:
        for name in files:
            if not present(os.path.join(SHARED, "content/cal3d", model, name)):
                continue
            with open(os.path.join(SHARED, "content/cal3d", model, name), "rb") as f:
                data = bytes([selectors[os.path.splitext(name)[1]]]) + f.read()
            write(cal3d_out, name, data)


if __name__ == "__main__":
    main()
