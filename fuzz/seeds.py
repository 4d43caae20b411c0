#!/usr/bin/env python3
"""Writes the reader fuzz targets' seeds (fuzz/corpus-mesh, -image, -points,
-lsp, -import, -lsp-dispatch): small files at the formats' odd but valid corners, so the fuzzers start
inside each format rather than at its magic number (tests/fuzz_seeds_test.cpp
reads each with its reader). Files named *_refused.* are refused with a
reason; regression_* are inputs the fuzzers once broke a reader with. Run it
again after a change here; the files are committed beside it. Images are 2:1,
so that they are maps as well as textures."""
import base64
import json
import os
import struct
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))


def put(kind, name, data):
    folder = os.path.join(HERE, "corpus-" + kind)
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, name), "wb") as f:
        f.write(data if isinstance(data, bytes) else data.encode())


TETRA_V = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)]
TETRA_F = [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]


def meshes():
    tris = [[TETRA_V[i] for i in f] for f in TETRA_F]
    # Binary STL, normals left zero; then one whose header starts "solid".
    body = b"".join(struct.pack("<12fH", 0, 0, 0, *[c for v in t for c in v], 0) for t in tris)
    put("mesh", "tetra_binary.stl", b"\0" * 80 + struct.pack("<I", len(tris)) + body)
    put("mesh", "tetra_binary_solid_header.stl", b"solid but binary".ljust(80, b" ") + struct.pack("<I", len(tris)) + body)
    facets = "".join("  facet normal 0 0 0\n\touter loop\n" + "".join(f"   vertex {x:g} {y:g} {z:g}\n" for x, y, z in t)
                     + "\tendloop\n  endfacet\n" for t in tris)
    put("mesh", "tetra_ascii.stl", "solid tetra\n" + facets + "endsolid tetra\n")
    put("mesh", "tetra_ascii_crlf_exponents.stl",
        ("solid\r\n" + facets.replace("vertex 1 ", "vertex 1.0e+00 ") + "endsolid\r\n").replace("\n", "\r\n"))
    # OBJ: v/vt/vn forms, negative indices, a quad fanned, comments, groups.
    put("mesh", "cube_mixed_faces.obj",
        "# a cube\nmtllib none.mtl\no cube\n" + "".join(f"v {x} {y} {z}\n" for x in (0, 1) for y in (0, 1) for z in (0, 1))
        + "vt 0 0\nvn 0 0 1\ng sides\ns off\n"
        "f 1/1/1 2/1/1 4/1/1 3/1/1\nf 5//1 7//1 8//1 6//1\nf 1 5 6 2\nf -6 -2 -1 -5\n"
        "f 1 3 7 5\nf 2 6 8\nf 2 8 4\n")
    put("mesh", "tetra_no_trailing_newline.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4")

    # glTF: positions and indices in one data: buffer, with strips, fans, a
    # byte stride, a sparse accessor, a mirroring node and a node hierarchy.
    pos = struct.pack("<12f", *[c for v in TETRA_V for c in v])
    strided = b"".join(struct.pack("<3f", *v) + b"\xee" * 4 for v in TETRA_V)
    idx_list = struct.pack("<12H", *[i for f in TETRA_F for i in f])
    idx_strip = struct.pack("<6B", 0, 2, 1, 3, 0, 2)
    idx_fan = struct.pack("<5I", 0, 2, 1, 3, 2)
    sparse_idx = struct.pack("<H", 3)
    sparse_val = struct.pack("<3f", 0, 0, 2)
    parts = [pos, strided, idx_list, idx_strip, idx_fan, sparse_idx, sparse_val]
    views, blob = [], b""
    for i, p in enumerate(parts):
        while len(blob) % 4:
            blob += b"\0"
        view = {"buffer": 0, "byteOffset": len(blob), "byteLength": len(p)}
        if i == 1:
            view["byteStride"] = 16
        views.append(view)
        blob += p
    lo, hi = [0, 0, 0], [1, 1, 1]
    doc = {
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0, 1]}],
        "nodes": [{"mesh": 0, "children": [2]}, {"mesh": 1, "scale": [-1, 1, 1], "translation": [3, 0, 0]},
                  {"mesh": 1, "matrix": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, -3, 1]}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 2},
                                   {"attributes": {"POSITION": 1}, "indices": 3, "mode": 5}]},
                   {"primitives": [{"attributes": {"POSITION": 0}, "indices": 5, "mode": 6},
                                   {"attributes": {"POSITION": 0}}]}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": lo, "max": hi},
            {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3", "min": lo, "max": hi},
            {"bufferView": 2, "componentType": 5123, "count": 12, "type": "SCALAR"},
            {"bufferView": 3, "componentType": 5121, "count": 6, "type": "SCALAR"},
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": lo, "max": [1, 1, 2],
             "sparse": {"count": 1, "indices": {"bufferView": 5, "componentType": 5123},
                        "values": {"bufferView": 6}}},
            {"bufferView": 4, "componentType": 5125, "count": 5, "type": "SCALAR"},
        ],
        "bufferViews": views,
        "buffers": [{"byteLength": len(blob),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}],
    }
    put("mesh", "strips_fans_mirror.gltf", json.dumps(doc, indent=1))
    # Sparse positions, which sdfc refuses with a reason (docs/mesh_in.md).
    sparse = json.loads(json.dumps(doc))
    sparse["meshes"][1]["primitives"][0]["attributes"]["POSITION"] = 4
    put("mesh", "sparse_positions_refused.gltf", json.dumps(sparse, indent=1))
    # The same as GLB: the buffer in the binary chunk.
    doc_glb = json.loads(json.dumps(doc))
    del doc_glb["buffers"][0]["uri"]
    js = json.dumps(doc_glb).encode()
    js += b" " * (-len(js) % 4)
    bin_ = blob + b"\0" * (-len(blob) % 4)
    glb = struct.pack("<I", len(js)) + b"JSON" + js + struct.pack("<I", len(bin_)) + b"BIN\0" + bin_
    put("mesh", "strips_fans_mirror.glb", b"glTF" + struct.pack("<II", 2, 12 + len(glb)) + glb)


def png(width, height, depth, colour_type, rows):
    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
    raw = b"".join(b"\0" + r for r in rows)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, depth, colour_type, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))


def exr(width, height, line_order, channels="BGR", half=False):
    def attr(name, kind, data):
        return name.encode() + b"\0" + kind.encode() + b"\0" + struct.pack("<i", len(data)) + data
    ptype = 1 if half else 2
    chlist = b"".join(c.encode() + b"\0" + struct.pack("<iB3xii", ptype, 0, 1, 1) for c in sorted(channels)) + b"\0"
    box = struct.pack("<4i", 0, 0, width - 1, height - 1)
    header = (b"\x76\x2f\x31\x01" + struct.pack("<I", 2) + attr("channels", "chlist", chlist)
              + attr("compression", "compression", b"\0") + attr("dataWindow", "box2i", box)
              + attr("displayWindow", "box2i", box) + attr("lineOrder", "lineOrder", bytes([line_order]))
              + attr("pixelAspectRatio", "float", struct.pack("<f", 1)) + attr("screenWindowCenter", "v2f", struct.pack("<2f", 0, 0))
              + attr("screenWindowWidth", "float", struct.pack("<f", 1)) + b"\0")
    blocks = []
    for y in range(height):
        row = b""
        for c in sorted(channels):
            for x in range(width):
                v = 0.25 * (x + 1) + y + {"R": 0, "G": 0.5, "B": 1}.get(c, 0)
                row += struct.pack("<e" if half else "<f", v)
        blocks.append(struct.pack("<ii", y, len(row)) + row)
    order = list(range(height)) if line_order == 0 else list(reversed(range(height)))
    offset = len(header) + 8 * height
    table, body = {}, b""
    for y in order:
        table[y] = offset + len(body)
        body += blocks[y]
    return header + b"".join(struct.pack("<Q", table[y]) for y in range(height)) + body


def images():
    put("image", "gray_8bit.png", png(3, 2, 8, 0, [bytes([0, 128, 255]), bytes([1, 2, 3])]))
    put("image", "rgb_16bit.png", png(2, 2, 16, 2, [struct.pack(">6H", 0, 1, 65535, 300, 40000, 7)] * 2))
    put("image", "rgba_8bit.png", png(2, 1, 8, 6, [bytes([255, 0, 0, 128, 0, 255, 0, 255])]))
    put("image", "gray_alpha_16bit.png", png(1, 2, 16, 4, [struct.pack(">2H", 1000, 65535)] * 2))
    rows = b"".join(bytes([128, 64, 32, 129]) * 4 for _ in range(2))
    put("image", "flat_rows.hdr", b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 4\n" + rows)
    # New-style run-length rows (width 8..32767): each channel a run and a literal.
    rle_row = b"\x02\x02\x00\x08" + b"".join(bytes([0x80 + 6, v, 2, v, v + 1]) for v in (100, 50, 25, 129))
    put("image", "rle_rows.hdr", b"#?RGBE\nEXPOSURE=1.0\nFORMAT=32-bit_rle_rgbe\n\n-Y 4 +X 8\n" + rle_row * 4)
    put("image", "increasing_y.exr", exr(4, 2, 0))
    put("image", "decreasing_y.exr", exr(4, 2, 1))
    put("image", "half_rgba.exr", exr(4, 2, 0, "RGBA", half=True))
    put("image", "one_channel_y.exr", exr(4, 2, 0, "Y"))


def points():
    put("points", "header_commas.csv", "x,y,z\n0,0,0\n1.5,-2,3e2\n")
    put("points", "semicolons_scale.csv", "# positions and scales\n0;0;0;1\n\n+1;2;3;0.5\n")
    put("points", "spaces_tabs_crlf.csv", "1 2 3\r\n4\t5\t6\r\n  7   8   9  \r\n")
    put("points", "bom_header.csv", "\ufeffpx, py, pz, s\n-0.25, .5, 1., 2\n")
    put("points", "no_final_newline.csv", "1,2,3")


def lsp():
    def frame(obj, sep="\r\n", extra=""):
        body = json.dumps(obj).encode()
        return (f"Content-Length: {len(body)}{sep}{extra}{sep}").encode() + body
    init = {"jsonrpc": "2.0", "id": 1, "method": "initialize", "params": {"capabilities": {}}}
    opened = {"jsonrpc": "2.0", "method": "textDocument/didOpen",
              "params": {"textDocument": {"uri": "file:///s.sdf", "languageId": "sdf", "version": 1,
                                          "text": "scene { sphere(radius: 1) }\n"}}}
    put("lsp", "two_frames.txt", frame(init) + frame(opened))
    put("lsp", "content_type_lowercase.txt",
        frame(init, extra="Content-Type: application/vscode-jsonrpc; charset=utf-8\r\n").replace(b"Content-Length", b"content-length"))
    put("lsp", "bare_newlines_blank_lines.txt", b"\n\n" + frame(init, sep="\n") + b"\n" + frame({"jsonrpc": "2.0", "method": "exit"}, sep="\n"))
    put("lsp", "batch_and_unicode.txt", frame([init, {"jsonrpc": "2.0", "id": "\u00e9", "method": "shutdown"}]))


def imports():
    # A scene and the files it imports, cut at NUL bytes: main.sdf, 1.sdf, 2.sdf...
    def files(*parts):
        return b"\0".join(p.encode() for p in parts)
    put("import", "diamond_aliases.sdf", files(
        'import "1.sdf" as a\nimport "2.sdf" as b\nscene { a.post b.leg(2) }\n',
        'import "2.sdf" as b\nlet post = b.leg(h: 1)\n',
        'let leg(h, w: 0.2) = box(size: [w, h, w])\n'))
    put("import", "no_alias_numbers_materials.sdf", files(
        'import "1.sdf"\nscene { sphere(radius: r, material: red) }\n',
        'let r = 1.5\nlet red = diffuse(albedo: [0.8, 0.1, 0.1])\n'))
    put("import", "nested_three_deep.sdf", files(
        'import "1.sdf" as one\nscene { one.ball }\n',
        'import "2.sdf" as two\nlet ball = two.ball\n',
        'import "3.sdf" as three\nlet ball = translate([0, 1, 0]) { three.ball }\n',
        'let ball = sphere(radius: 0.5)\n'))
    put("import", "same_file_twice.sdf", files(
        'import "1.sdf" as x\nimport "1.sdf" as y\nimport "./1.sdf" as z\nscene { x.s y.s z.s }\n',
        '// a comment\nlet s = torus(major: 1, minor: 0.25)\n'))
    put("import", "cycle_refused.sdf", files(
        'import "1.sdf" as a\nscene { sphere(radius: 1) }\n',
        'import "2.sdf" as b\n',
        'import "1.sdf" as c\n'))
    put("import", "missing_and_statement_refused.sdf", files(
        'import "1.sdf" as a\nimport "9.sdf" as n\nscene { a.p }\n',
        'let p = sphere(radius: 1)\nscene { p }\n'))


def lsp_dispatch():
    # Message bodies, one a line, sent after initialize and the opening of
    # file:///sdfc_lsp_fuzz/s.sdf holding (lines from 0):
    #   let r = 1
    #   let f(x, y: 2) = sphere(radius: x * y)
    #   scene { f(r) box(size: 1) }
    uri = "file:///sdfc_lsp_fuzz/s.sdf"

    def request(i, method, **params):
        return json.dumps({"jsonrpc": "2.0", "id": i, "method": method,
                           "params": {"textDocument": {"uri": uri}, **params}})

    def at(line, character):
        return {"line": line, "character": character}
    put("lsp-dispatch", "every_request.txt", "\n".join([
        request(1, "textDocument/hover", position=at(2, 8)),
        request(2, "textDocument/hover", position=at(1, 26)),
        request(3, "textDocument/definition", position=at(2, 10)),
        request(4, "textDocument/references", position=at(0, 4), context={"includeDeclaration": True}),
        request(5, "textDocument/documentHighlight", position=at(1, 6)),
        request(6, "textDocument/prepareRename", position=at(0, 4)),
        request(7, "textDocument/rename", position=at(0, 4), newName="radius2"),
        request(8, "textDocument/completion", position=at(2, 26)),
        request(9, "textDocument/signatureHelp", position=at(2, 10)),
        request(10, "textDocument/documentSymbol"),
        request(11, "textDocument/formatting", options={"tabSize": 2, "insertSpaces": True}),
    ]) + "\n")
    change = {"jsonrpc": "2.0", "method": "textDocument/didChange",
              "params": {"textDocument": {"uri": uri, "version": 2},
                         "contentChanges": [{"range": {"start": at(0, 8), "end": at(0, 9)}, "text": "2.5"},
                                            {"range": {"start": at(2, 27), "end": at(2, 27)},
                                             "text": " torus(major: r, minor: 0.2)"}]}}
    put("lsp-dispatch", "edits_then_requests.txt", "\n".join([
        json.dumps(change),
        request(1, "textDocument/hover", position=at(2, 30)),
        request(2, "textDocument/completion", position=at(2, 40)),
        json.dumps({"jsonrpc": "2.0", "method": "textDocument/didChange",
                    "params": {"textDocument": {"uri": uri, "version": 3},
                               "contentChanges": [{"text": "scene { sphère(radius: 1) }\n"}]}}),
        request(3, "textDocument/documentSymbol"),
        request("four", "textDocument/formatting", options={}),
    ]) + "\n")
    put("lsp-dispatch", "second_document_and_close.txt", "\n".join([
        json.dumps({"jsonrpc": "2.0", "method": "textDocument/didOpen",
                    "params": {"textDocument": {"uri": "untitled:two", "languageId": "sdf", "version": 1,
                                                "text": 'import "lib.sdf" as l\nscene { l.x }\n'}}}),
        json.dumps({"jsonrpc": "2.0", "id": 1, "method": "textDocument/hover",
                    "params": {"textDocument": {"uri": "untitled:two"}, "position": at(1, 9)}}),
        json.dumps({"jsonrpc": "2.0", "method": "textDocument/didClose", "params": {"textDocument": {"uri": "untitled:two"}}}),
        request(2, "textDocument/references", position=at(1, 7), context={"includeDeclaration": False}),
        json.dumps({"jsonrpc": "2.0", "method": "$/cancelRequest", "params": {"id": 99}}),
    ]) + "\n")


if __name__ == "__main__":
    meshes()
    images()
    points()
    lsp()
    imports()
    lsp_dispatch()
