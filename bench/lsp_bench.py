#!/usr/bin/env python3
"""`sdfc lsp` latency and memory, driven over stdio as an editor would.

  1. Diagnostics latency: 200 edits to examples/castle.sdf (one number changed
     in place, incremental sync), each timed from sending didChange to
     receiving the publishDiagnostics for that version. Target: median < 50 ms.
  2. Memory over 10,000 edits: each edit is followed by a hover (so every
     version is analysed, not only the ones diagnostics get to); the server's
     resident set (VmRSS) is sampled every 500 edits. Target: flat.
Writes bench/results/lsp_bench.txt. Usage: lsp_bench.py [SDFC] [--edits N]
"""
import argparse
import os
import statistics
import sys
import time

here = os.path.dirname(os.path.abspath(__file__))
root = os.path.dirname(here)
sys.path.insert(0, os.path.join(root, "tests"))
from lsp_client import LspClient  # noqa: E402

ap = argparse.ArgumentParser()
ap.add_argument("sdfc", nargs="?", default=os.path.join(root, "build", "cli", "sdfc"))
ap.add_argument("--edits", type=int, default=10000)
ap.add_argument("--latency-edits", type=int, default=200)
args = ap.parse_args()


def rss_kib(pid):
    for line in open(f"/proc/{pid}/status"):
        if line.startswith("VmRSS:"):
            return int(line.split()[1])
    return 0


text = open(os.path.join(root, "examples", "castle.sdf"), encoding="utf-8").read()
uri = "file:///bench/castle.sdf"
c = LspClient([args.sdfc, "lsp"])
c.initialize()
c.notify("textDocument/didOpen", {"textDocument": {"uri": uri, "languageId": "sdf", "version": 1, "text": text}})
c.wait_notification("textDocument/publishDiagnostics", lambda m: m["params"]["uri"] == uri)

# An edit site: the value of `let half = 5` (replaced by 5, 6, 7, ...: same length
# for one digit, so the range stays valid).
offset = text.index("let half = ") + len("let half = ")
line = text.count("\n", 0, offset)
col = offset - (text.rfind("\n", 0, offset) + 1)
edit_range = {"start": {"line": line, "character": col}, "end": {"line": line, "character": col + 1}}
version = 1


def edit(k):
    global version
    version += 1
    c.notify("textDocument/didChange", {"textDocument": {"uri": uri, "version": version},
                                        "contentChanges": [{"range": edit_range, "text": str(5 + k % 4)}]})
    return version


latencies = []
for k in range(args.latency_edits):
    t0 = time.perf_counter()
    v = edit(k)
    t1, _ = c.wait_notification("textDocument/publishDiagnostics",
                                lambda m: m["params"]["uri"] == uri and m["params"].get("version") == v)
    latencies.append((t1 - t0) * 1000)

samples = []
hover_pos = {"line": line, "character": col - 3}
t_start = time.perf_counter()
for k in range(args.edits):
    edit(k)
    c.request("textDocument/hover", {"textDocument": {"uri": uri}, "position": hover_pos})
    if (k + 1) % 500 == 0:
        samples.append((k + 1, rss_kib(c.proc.pid)))
edit_seconds = time.perf_counter() - t_start
c.request("shutdown")
c.notify("exit")
code = c.close()

latencies.sort()
median = statistics.median(latencies)
p90 = latencies[int(0.9 * (len(latencies) - 1))]
first, last = samples[0][1], samples[-1][1]
growth = (last - first) / first if first else 0
lines = [
    f"sdfc lsp benchmark, castle.sdf ({len(text)} bytes), {os.cpu_count()} cores",
    f"diagnostics after a change: median {median:.2f} ms, p90 {p90:.2f} ms, max {latencies[-1]:.2f} ms "
    f"over {len(latencies)} edits (target: median < 50 ms)",
    f"{args.edits} edits + hovers in {edit_seconds:.1f} s ({edit_seconds / args.edits * 1000:.2f} ms each)",
    "RSS (KiB) by edits: " + ", ".join(f"{n}:{r}" for n, r in samples),
    f"RSS after {samples[0][0]} edits {first} KiB, after {samples[-1][0]} edits {last} KiB: "
    f"growth {growth * 100:+.1f}% (target: flat)",
    f"server exit code {code}",
]
print("\n".join(lines))
os.makedirs(os.path.join(here, "results"), exist_ok=True)
with open(os.path.join(here, "results", "lsp_bench.txt"), "w") as f:
    f.write("\n".join(lines) + "\n")
sys.exit(0 if code == 0 else 1)
