#!/usr/bin/env python3
"""`sdfc lsp` driven over stdio as an editor would (CTest: lsp_protocol).

Usage: lsp_test.py SDFC SOURCE_DIR
"""
import json
import os
import re
import subprocess
import sys
import tempfile
import urllib.parse

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from lsp_client import LspClient  # noqa: E402

sdfc, root = sys.argv[1], sys.argv[2]
passed = failed = 0


def check(name, condition, detail=""):
    global passed, failed
    if condition:
        passed += 1
    else:
        failed += 1
        print(f"FAIL {name} {detail}")


def pos(text, needle, nth=0, delta=0):
    """LSP position (UTF-16) of the nth occurrence of needle, plus delta characters."""
    i = -1
    for _ in range(nth + 1):
        i = text.index(needle, i + 1)
    i += delta
    line = text.count("\n", 0, i)
    col = i - (text.rfind("\n", 0, i) + 1)
    return {"line": line, "character": len(text[i - col:i].encode("utf-16-le")) // 2}


uri = "file:///tmp/lsp_test/scene.sdf"
text = open(os.path.join(root, "examples", "castle.sdf"), encoding="utf-8").read()
doc = {"textDocument": {"uri": uri}}

# ---- a session ---------------------------------------------------------------
c = LspClient([sdfc, "lsp"])
r = c.request("textDocument/hover", {**doc, "position": {"line": 0, "character": 0}})
check("request before initialize", r.get("error", {}).get("code") == -32002, r)
init = c.initialize()
caps = init["result"]["capabilities"]
check("incremental sync", caps["textDocumentSync"]["change"] == 2, caps)
check("second initialize", c.request("initialize", {"capabilities": {}}).get("error", {}).get("code") == -32600)

c.notify("textDocument/didOpen", {"textDocument": {"uri": uri, "languageId": "sdf", "version": 1, "text": text}})
_, d = c.wait_notification("textDocument/publishDiagnostics", lambda m: m["params"]["uri"] == uri)
errors = [x for x in d["params"]["diagnostics"] if x["severity"] == 1]
check("castle has no errors", not errors, errors)

# Hover on a primitive: signature, parameters and defaults from the catalogue.
h = c.request("textDocument/hover", {**doc, "position": pos(text, "cylinder(", delta=2)})["result"]
value = h["contents"]["value"] if h else ""
check("hover primitive signature", "cylinder(" in value and "radius" in value and "height" in value, value)
check("hover primitive exactness", "exact" in value.lower(), value)

# Hover on a setting's parameter name: its default and limit.
h = c.request("textDocument/hover", {**doc, "position": pos(text, "fov:", delta=1)})["result"]
value = h["contents"]["value"] if h else ""
check("hover parameter", "fov" in value and "default 40" in value, value)

# Completion inside an argument list: parameter names with defaults.
probe = text + "\nlet probe = sphere()\n"
c.notify("textDocument/didChange", {"textDocument": {"uri": uri, "version": 2},
                                    "contentChanges": [{"text": probe}]})
items = c.request("textDocument/completion", {**doc, "position": pos(probe, "sphere()", delta=7)})["result"]["items"]
labels = {i["label"]: i for i in items}
check("complete parameter name", "radius" in labels and labels["radius"].get("insertText") == "radius: ",
      list(labels)[:10])
check("complete names in scope", "stone" in labels, list(labels)[:20])
sig = c.request("textDocument/signatureHelp", {**doc, "position": pos(probe, "sphere()", delta=7)})["result"]
check("signature help", sig and sig["signatures"][0]["label"].startswith("sphere(radius"), sig)

# Incremental edit: a misspelt parameter; diagnostics as `sdfc check` words them.
start = pos(probe, "sphere()", delta=7)
c.notify("textDocument/didChange", {"textDocument": {"uri": uri, "version": 3},
                                    "contentChanges": [{"range": {"start": start, "end": start}, "text": "radus: 1"}]})
_, d = c.wait_notification("textDocument/publishDiagnostics",
                           lambda m: m["params"]["uri"] == uri and m["params"].get("version") == 3)
msgs = [x["message"] for x in d["params"]["diagnostics"] if x["severity"] == 1]
edited = probe.replace("sphere()", "sphere(radus: 1)")
tmp = "/tmp/lsp_test_scene.sdf"
open(tmp, "w").write(edited)
cli = subprocess.run([sdfc, "check", tmp], capture_output=True, text=True).stderr
cli_msgs = re.findall(r": error: (.*)", cli)
check("diagnostics equal sdfc check", msgs == cli_msgs and msgs, (msgs, cli_msgs))
diag = [x for x in d["params"]["diagnostics"] if "radus" in x["message"]]
check("diagnostic range", diag and diag[0]["range"]["start"] == start, diag)

# Definition, references, rename of a let name.
text = edited
use = pos(text, "stone", nth=1)
r = c.request("textDocument/definition", {**doc, "position": use})["result"]
check("definition", r and r["range"]["start"] == pos(text, "let stone", delta=4), r)
refs = c.request("textDocument/references", {**doc, "position": use,
                                              "context": {"includeDeclaration": True}})["result"]
check("references", len(refs) == text.count("stone"), (len(refs), text.count("stone")))
r = c.request("textDocument/rename", {**doc, "position": use, "newName": "granite"})["result"]
edits = r["changes"][uri]
check("rename edits", len(edits) == len(refs) and all(e["newText"] == "granite" for e in edits), r)
r = c.request("textDocument/rename", {**doc, "position": use, "newName": "sphere"})
check("rename to a built-in refused", r.get("error", {}).get("code") == -32803, r)
# A 30,000-character name (std::regex overflowed the stack on it): renamed, no crash.
r = c.request("textDocument/rename", {**doc, "position": use, "newName": "g" * 30000})
check("rename to a very long name", "result" in r and r["result"]["changes"][uri][0]["newText"] == "g" * 30000,
      str(r)[:200])
r = c.request("textDocument/rename", {**doc, "position": use, "newName": "1" * 30000})
check("rename to a very long bad name refused", r.get("error", {}).get("code") == -32803, str(r)[:200])

# Parametric definitions and imports, in a real directory with a space in its name.
tmpdir = tempfile.mkdtemp(prefix="lsp params ")
with open(os.path.join(tmpdir, "parts.sdf"), "w") as f:
    f.write("let post(h, r: 0.2) = cylinder(radius: r, height: h)\n")
ptext = ('import "parts.sdf" as parts\n'
         'let tower(height, radius: 1) = union {\n'
         '  cylinder(radius: radius, height: height)\n'
         '  translate([0, height / 2, 0]) { parts.post(height) }\n'
         '}\n'
         'scene { tower(5) tower(7, radius: 1.3) }\n')
puri = "file://" + urllib.parse.quote(os.path.join(tmpdir, "castle.sdf"))
pdoc = {"textDocument": {"uri": puri}}
c.notify("textDocument/didOpen", {"textDocument": {"uri": puri, "languageId": "sdf", "version": 1, "text": ptext}})
_, d = c.wait_notification("textDocument/publishDiagnostics", lambda m: m["params"]["uri"] == puri)
errors = [x for x in d["params"]["diagnostics"] if x["severity"] == 1]
check("parametric scene with an import has no errors", not errors, errors)
r = c.request("textDocument/definition", {**pdoc, "position": pos(ptext, "height", nth=2)})["result"]
check("definition of a parameter", r and r["range"]["start"] == pos(ptext, "height"), r)
refs = c.request("textDocument/references", {**pdoc, "position": pos(ptext, "height", nth=3),
                                              "context": {"includeDeclaration": True}})["result"]
check("references of a parameter", len(refs) == 4, refs)
r = c.request("textDocument/rename", {**pdoc, "position": pos(ptext, "radius"), "newName": "width"})["result"]
starts = sorted((e["range"]["start"]["line"], e["range"]["start"]["character"]) for e in r["changes"][puri])
want = sorted((p["line"], p["character"]) for p in
              [pos(ptext, "radius"), pos(ptext, "radius", nth=2), pos(ptext, "radius", nth=3)])
check("rename a parameter (not the primitive's argument name)", starts == want, (starts, want))
h = c.request("textDocument/hover", {**pdoc, "position": pos(ptext, "tower(5)", delta=1)})["result"]
value = h["contents"]["value"] if h else ""
check("hover a definition's call", "tower(height: a number, radius: a number = 1)" in value, value)
items = c.request("textDocument/completion", {**pdoc, "position": pos(ptext, "tower(7", delta=6)})["result"]["items"]
labels = {i["label"] for i in items}
check("complete a definition's parameters", {"height", "radius"} <= labels, sorted(labels)[:20])
r = c.request("textDocument/definition", {**pdoc, "position": pos(ptext, "parts.post", delta=7)})["result"]
check("definition across files", r and r["uri"].endswith("/parts.sdf") and "%20" in r["uri"] and
      r["range"]["start"] == {"line": 0, "character": 4}, r)

# Hover on a call of an imported definition: its signature and text (it was
# null; issue 47 item 19).
h = c.request("textDocument/hover", {**pdoc, "position": pos(ptext, "parts.post", delta=7)})["result"]
value = h["contents"]["value"] if h else ""
check("hover an imported definition's call",
      "parts.post(h: a number, r: a number = 0.2)" in value and "parts.sdf" in value and
      "cylinder(radius: r, height: h)" in value, value)

# A document over the server's size limit is kept, not analysed: one error
# diagnostic says so, requests on it fail, and it is analysed again once
# an edit brings it under (a 28 MB document took 7.7 GB, then the server aborted).
buri = "file:///tmp/lsp_test/big.sdf"
big = "scene { sphere(radius: 1) }\n" + "// padding\n" * 400000
c.notify("textDocument/didOpen", {"textDocument": {"uri": buri, "languageId": "sdf", "version": 1, "text": big}})
_, d = c.wait_notification("textDocument/publishDiagnostics", lambda m: m["params"]["uri"] == buri)
diags = d["params"]["diagnostics"]
check("a document over the limit: one error saying so", len(diags) == 1 and diags[0]["severity"] == 1 and
      "the language server analyses documents up to 4.0 MiB" in diags[0]["message"], diags)
r = c.request("textDocument/hover", {"textDocument": {"uri": buri}, "position": {"line": 0, "character": 9}})
check("a request on a document over the limit fails", r.get("error", {}).get("code") == -32803 and
      "4.0 MiB" in r["error"]["message"], str(r)[:300])
c.notify("textDocument/didChange", {"textDocument": {"uri": buri, "version": 2}, "contentChanges": [
    {"range": {"start": {"line": 1, "character": 0}, "end": {"line": 400001, "character": 0}}, "text": ""}]})
_, d = c.wait_notification("textDocument/publishDiagnostics",
                           lambda m: m["params"]["uri"] == buri and m["params"].get("version") == 2)
check("under the limit again: analysed", d["params"]["diagnostics"] == [], d["params"]["diagnostics"])
r = c.request("textDocument/hover", {"textDocument": {"uri": buri}, "position": {"line": 0, "character": 9}})
check("under the limit again: hover answers", r.get("result") is not None, str(r)[:300])

# An import diamond (each file importing the next twice, `as x` and `as y`):
# the server answered nothing (3.5 GB) at 30 files; each file is bound once now,
# and a name through the second alias still goes to its definition.
ddir = tempfile.mkdtemp(prefix="lsp diamond ")
for i in range(30):
    with open(os.path.join(ddir, "f%d.sdf" % i), "w") as f:
        if i < 29:
            f.write('import "f%d.sdf" as x\nimport "f%d.sdf" as y\nlet r = x.r + 0 * y.r\n'
                    'let ball = sphere(radius: y.r)\n' % (i + 1, i + 1))
        else:
            f.write("let r = 0.5\nlet ball = sphere(radius: r)\n")
dtext = 'import "f0.sdf" as x\nimport "f0.sdf" as y\nscene { x.ball y.ball }\n'
duri = "file://" + urllib.parse.quote(os.path.join(ddir, "main.sdf"))
c.notify("textDocument/didOpen", {"textDocument": {"uri": duri, "languageId": "sdf", "version": 1, "text": dtext}})
_, d = c.wait_notification("textDocument/publishDiagnostics", lambda m: m["params"]["uri"] == duri)
check("import diamond has no errors", not [x for x in d["params"]["diagnostics"] if x["severity"] == 1], d)
r = c.request("textDocument/definition", {"textDocument": {"uri": duri}, "position": pos(dtext, "y.ball", delta=3)})["result"]
check("definition through the second alias", r and r["uri"].endswith("/f0.sdf") and
      r["range"]["start"] == {"line": 3, "character": 4}, r)

# A warning inside an imported file: on the import that names the file (the
# second here), as "file:line:col: message" relative to the document (it was
# the first import, with the absolute path, and the message said twice).
with open(os.path.join(ddir, "warm.sdf"), "w") as f:
    f.write("let blob = union(smooth: 0.2) { sphere(radius: 1) box(size: 1) }\n")
wtext = 'import "f0.sdf" as x\nimport "warm.sdf" as w\nscene { x.ball w.blob }\n'
wuri = "file://" + urllib.parse.quote(os.path.join(ddir, "warned.sdf"))
c.notify("textDocument/didOpen", {"textDocument": {"uri": wuri, "languageId": "sdf", "version": 1, "text": wtext}})
_, d = c.wait_notification("textDocument/publishDiagnostics", lambda m: m["params"]["uri"] == wuri)
warns = [x for x in d["params"]["diagnostics"] if x.get("code") == "bound"]
check("an imported file's warning, once, on its import", len(warns) == 1 and
      warns[0]["range"]["start"] == pos(wtext, '"warm.sdf"') and
      warns[0]["message"].startswith("warm.sdf:1:12: smooth 'union' gives a distance bound") and
      [r["message"] for r in warns[0]["relatedInformation"]] == ["here"] and
      warns[0]["relatedInformation"][0]["location"]["range"]["start"] == {"line": 0, "character": 11}, warns)

# Profiles and deformations: hover from the catalogue and the analysis, completion.
xuri = "file:///tmp/lsp_test/profiles.sdf"
xdoc = {"textDocument": {"uri": xuri}}
xtext = open(os.path.join(root, "examples", "profiles_and_twist.sdf"), encoding="utf-8").read()
c.notify("textDocument/didOpen", {"textDocument": {"uri": xuri, "languageId": "sdf", "version": 1, "text": xtext}})
_, d = c.wait_notification("textDocument/publishDiagnostics", lambda m: m["params"]["uri"] == xuri)
check("profiles example has no errors", not [x for x in d["params"]["diagnostics"] if x["severity"] == 1], d)
h = c.request("textDocument/hover", {**xdoc, "position": pos(xtext, "rect(", delta=1)})["result"]
value = h["contents"]["value"] if h else ""
check("hover a profile", "2D profile" in value and "size: 2-vector" in value, value)
h = c.request("textDocument/hover", {**xdoc, "position": pos(xtext, "twist(", delta=1)})["result"]
value = h["contents"]["value"] if h else ""
check("hover twist: its stretch", "bound" in value and "stretches space by up to" in value, value)
probe = xtext + "\nlet probe = extrude(depth: 1) { poly }\n"
c.notify("textDocument/didChange", {"textDocument": {"uri": xuri, "version": 2}, "contentChanges": [{"text": probe}]})
items = c.request("textDocument/completion", {**xdoc, "position": pos(probe, "{ poly }", delta=6)})["result"]["items"]
check("complete a profile", "polygon" in {i["label"] for i in items}, [i["label"] for i in items][:20])

# Symbols and formatting.
syms = c.request("textDocument/documentSymbol", doc)["result"]
names = [s["name"] for s in syms]
check("document symbols", "scene" in names and "stone" in names and "camera" in names, names)
messy = "scene{sphere( radius:1 )   // r\n}\n"
c.notify("textDocument/didChange", {"textDocument": {"uri": uri, "version": 4}, "contentChanges": [{"text": messy}]})
r = c.request("textDocument/formatting", {**doc, "options": {"tabSize": 2, "insertSpaces": True}})["result"]
want = subprocess.run([sdfc, "fmt"], input=messy, capture_output=True, text=True).stdout
check("formatting equals sdfc fmt", r and r[0]["newText"] == want, r)
# Strings survive formatting (they were deleted: file("p.csv") became file()).
messy = 'scene{instances(positions:file("my points.csv")){sphere(radius:0.1)}}\n'
c.notify("textDocument/didChange", {"textDocument": {"uri": uri, "version": 5}, "contentChanges": [{"text": messy}]})
r = c.request("textDocument/formatting", {**doc, "options": {"tabSize": 2, "insertSpaces": True}})["result"]
check("formatting keeps strings", r and 'file("my points.csv")' in r[0]["newText"], r)
# A document with an import formats (the server died on Format Document: the
# formatter took the value of the import statement, which has none).
messy = 'import   "parts.sdf"  as parts\nscene{parts.post(2)}\n'
c.notify("textDocument/didChange", {"textDocument": {"uri": puri, "version": 2}, "contentChanges": [{"text": messy}]})
r = c.request("textDocument/formatting", {**pdoc, "options": {"tabSize": 2, "insertSpaces": True}})["result"]
check("formatting a document with an import", r and r[0]["newText"] ==
      'import "parts.sdf" as parts\nscene { parts.post(2) }\n', r)

# Malformed and out-of-order messages: protocol errors, never a crash.
c.send_raw(b"{not json")
check("parse error", c.wait(None)["error"]["code"] == -32700)
c.send({"jsonrpc": "2.0", "id": 900, "params": {}})
check("missing method", c.wait(900)["error"]["code"] == -32600)
check("unknown method", c.request("textDocument/nonsense", doc)["error"]["code"] == -32601)
r = c.request("textDocument/hover", {**doc})
check("missing position", r["error"]["code"] == -32602, r)
r = c.request("textDocument/hover", {"textDocument": {"uri": "file:///nowhere.sdf"}, "position": {"line": 0, "character": 0}})
check("document not open", r["error"]["code"] == -32602, r)
r = c.request("textDocument/hover", {**doc, "position": {"line": 99999, "character": 99999}})
check("position past the end", "result" in r, r)
c.send_raw(b"", header=b"Content-Type: x\r\n\r\n")  # a frame without a length: its body cannot be found
check("no content-length", c.wait(None)["error"]["code"] == -32700)
c.notify("textDocument/didChange", {"textDocument": {"uri": "file:///nowhere.sdf", "version": 1},
                                    "contentChanges": [{"text": "x"}]})
# Cancellation of many queued requests: each gets an answer or a cancelled error.
ids = [c.request_async("textDocument/hover", {**doc, "position": {"line": 0, "character": 2}}) for _ in range(20)]
for i in ids:
    c.notify("$/cancelRequest", {"id": i})
answers = [c.wait(i) for i in ids]
check("cancelled or answered", all("result" in a or a["error"]["code"] == -32800 for a in answers), answers[:2])
check("still alive", c.request("textDocument/documentSymbol", doc).get("result") is not None)

r = c.request("shutdown")
check("shutdown", "result" in r and r["result"] is None, r)
check("request after shutdown", c.request("textDocument/hover", {**doc, "position": {"line": 0, "character": 0}})["error"]["code"] == -32600)
c.notify("exit")
check("exit code 0 after shutdown", c.close() == 0)

# Exit without shutdown: exit code 1, as the protocol says.
c = LspClient([sdfc, "lsp"])
c.initialize()
c.notify("exit")
check("exit code 1 without shutdown", c.close() == 1)

# Garbage bytes: the server answers or ends, and never crashes.
c = LspClient([sdfc, "lsp"])
c.send_raw(b"Content-Length: 5\r\n\r\n\x00\xff\xfe{]")
c.send_raw(b"Content-Length: 99999999999999\r\n\r\n")
code = c.close()
check("garbage input ends cleanly", code in (0, 1), code)

# Every fuzz input (random bytes, deep nesting, broken syntax) opened and
# queried at 40 positions with every feature: answers or errors, never a crash.
import glob  # noqa: E402
c = LspClient([sdfc, "lsp"])
c.initialize()
features = ["hover", "completion", "signatureHelp", "definition", "references", "documentHighlight",
            "prepareRename"]
bad = []
files = sorted(glob.glob(os.path.join(root, "fuzz", "corpus", "*")) + glob.glob(os.path.join(root, "fuzz", "regressions", "*.sdf")))
for n, path in enumerate(files):
    data = open(path, "rb").read().decode("utf-8", "replace")
    u = f"file:///fuzz/{n}.sdf"
    c.notify("textDocument/didOpen", {"textDocument": {"uri": u, "languageId": "sdf", "version": 1, "text": data}})
    lines = data.split("\n")
    ids = []
    for k in range(40):
        line = (k * 7919) % max(1, len(lines))
        char = (k * 104729) % (len(lines[line]) + 2)
        for f in features:
            ids.append(c.request_async("textDocument/" + f, {"textDocument": {"uri": u},
                                                              "position": {"line": line, "character": char},
                                                              "context": {"includeDeclaration": True}}))
    ids.append(c.request_async("textDocument/documentSymbol", {"textDocument": {"uri": u}}))
    ids.append(c.request_async("textDocument/formatting", {"textDocument": {"uri": u}, "options": {}}))
    for i in ids:
        r = c.wait(i, timeout=60)
        if "error" in r and r["error"]["code"] not in (-32602, -32803):
            bad.append((os.path.basename(path), r["error"]))
check("fuzz inputs answered", not bad and c.proc.poll() is None, bad[:3])

# Issue 29: `// sdfc: allow(...)` is honoured as by `sdfc check`; a warning's name is its code.
u = "file:///tmp/lsp_test/allow.sdf"
allow = ("scene {\n  // sdfc: allow(bound)\n  union(smooth: 0.1) { sphere(radius: 1) box(size: 1) }\n"
         "  union(smooth: 0.2) { sphere(radius: 1) box(size: 1) }\n}\n")
c.notify("textDocument/didOpen", {"textDocument": {"uri": u, "languageId": "sdf", "version": 1, "text": allow}})
_, d = c.wait_notification("textDocument/publishDiagnostics", lambda m: m["params"]["uri"] == u)
warnings = [x for x in d["params"]["diagnostics"] if x["severity"] == 2]
check("allow pragma in the editor", len(warnings) == 1 and warnings[0]["range"]["start"]["line"] == 3 and
      warnings[0].get("code") == "bound", warnings)
c.request("shutdown")
c.notify("exit")
check("fuzz session exits cleanly", c.close() == 0)

# file("towers.csv") is read beside the document, whatever its URI spells:
# percent-encoded spaces and non-ASCII, file://localhost/, file:/ (issue 28: it
# was resolved against the URI string, a false error and false "never used").
import tempfile  # noqa: E402
import urllib.parse  # noqa: E402
with tempfile.TemporaryDirectory(prefix="lsp uri #1 \u00e9 ") as d:
    open(os.path.join(d, "towers.csv"), "w").write("0,0,0\n2,0,0\n")
    scene_text = 'let r = 0.4\nscene { instances(positions: file("towers.csv")) { sphere(radius: r) } }\n'
    scene_path = os.path.join(d, "scene.sdf")
    open(scene_path, "w").write(scene_text)
    cli = subprocess.run([sdfc, "check", scene_path], capture_output=True, text=True)
    check("uri: sdfc check is clean", cli.returncode == 0 and cli.stderr == "", cli.stderr)
    quoted = urllib.parse.quote(scene_path)
    c = LspClient([sdfc, "lsp"])
    c.initialize()
    for u in ("file://" + quoted, "file://localhost" + quoted, "file:" + quoted,
              "file://" + quoted.replace("%C3%A9", "%c3%a9")):
        c.notify("textDocument/didOpen", {"textDocument": {"uri": u, "languageId": "sdf", "version": 1, "text": scene_text}})
        _, m = c.wait_notification("textDocument/publishDiagnostics", lambda m: m["params"]["uri"] == u)
        check("uri: no false diagnostics for " + u, m["params"]["diagnostics"] == [], m["params"]["diagnostics"])
    # A file that is really missing is still an error, with its decoded path.
    u = "file://" + urllib.parse.quote(os.path.join(d, "other.sdf"))
    c.notify("textDocument/didOpen", {"textDocument": {"uri": u, "languageId": "sdf", "version": 1,
                                                       "text": scene_text.replace("towers", "missing")}})
    _, m = c.wait_notification("textDocument/publishDiagnostics", lambda m: m["params"]["uri"] == u)
    messages = [x["message"] for x in m["params"]["diagnostics"]]
    check("uri: a missing file names its decoded path",
          any(os.path.join(d, "missing.csv") in x for x in messages), messages)

    # With an error elsewhere the passes do not run: hover must not call a
    # smooth union exact (the warning-free file says it is a bound).
    smooth = "scene {\n  union(smooth: 0.3) { sphere(radius: 1) box(size: [1, 1, 1]) }\n  BROKEN\n}\n"
    for name, body in (("clean", smooth.replace("BROKEN", "")), ("broken", smooth.replace("BROKEN", "sphere(radus: 1)"))):
        u = f"file:///tmp/lsp_test/smooth_{name}.sdf"
        c.notify("textDocument/didOpen", {"textDocument": {"uri": u, "languageId": "sdf", "version": 1, "text": body}})
        c.wait_notification("textDocument/publishDiagnostics", lambda m: m["params"]["uri"] == u)
        h = c.request("textDocument/hover", {"textDocument": {"uri": u}, "position": pos(body, "union(", delta=2)})["result"]
        value = h["contents"]["value"] if h else ""
        if name == "clean":
            check("hover smooth union: a bound", "bound" in value and "exact Euclidean" not in value, value)
        else:
            check("hover smooth union with an error: not called exact", "exact Euclidean" not in value, value)

    # A message over the 64 MiB limit is skipped whole: the next request is answered.
    c.send_raw(b" " * ((64 << 20) + 1))
    try:
        r = c.request("textDocument/documentSymbol", {"textDocument": {"uri": "file:///tmp/lsp_test/smooth_clean.sdf"}})
    except TimeoutError as e:
        r = {"error": str(e)}
    check("after an oversized message the next request is answered", "result" in r, r)
    c.request("shutdown")
    c.notify("exit")
    check("uri session exits cleanly", c.close() == 0)

print(f"lsp_protocol: {passed + failed} checks")
print(f"{passed} passed, {failed} failed")
sys.exit(1 if failed else 0)
