#!/usr/bin/env python3
"""`sdfc fmt` over every example, docs snippet and fuzz input (CTest: fmt_meaning).

For each file that parses:
  - formatting is idempotent: fmt(fmt(x)) == fmt(x);
  - formatting keeps every comment (the comment texts, in order, are the same);
  - formatting never changes meaning: `sdfc compile --emit ir` prints the same
    dump before and after (line numbers aside), or the same error messages;
and the examples and docs snippets are already formatted (`fmt --check`).
Usage: fmt_test.py SDFC SOURCE_DIR
"""
import glob
import os
import re
import subprocess
import sys
import tempfile

sdfc, root = sys.argv[1], sys.argv[2]
failures = []
checked = skipped = 0


def run(args, text=None):
    p = subprocess.run([sdfc] + args, input=text, capture_output=True, timeout=120)
    return p.returncode, p.stdout, p.stderr


def fmt(data):
    rc, out, err = run(["fmt"], data)
    return out if rc == 0 else None


def comments(data):
    # Comment texts in order, by the lexer's rules: a line comment ends at LF or
    # at a lone CR (strings do not exist in .sdf).
    return re.findall(rb"//[^\n\r]*?(?=[ \t]*(?:\r|\n|$))|/\*.*?\*/", data, re.S)


def meaning(data, tmp):
    path = os.path.join(tmp, "scene.sdf")
    with open(path, "wb") as f:
        f.write(data)
    rc, out, err = run(["compile", path, "--emit", "ir", "-o", "-"])
    out = re.sub(rb"line \d+", b"line N", out)
    # Errors: the messages, without their positions, source lines and carets.
    messages = sorted(re.findall(rb": (?:error|warning): ([^\n]*)", err))
    return rc, out, messages


def check(name, data, must_be_formatted, tmp):
    global checked, skipped
    once = fmt(data)
    if once is None:
        skipped += 1
        return
    checked += 1
    twice = fmt(once)
    if twice != once:
        failures.append(f"{name}: not idempotent")
    if comments(once) != comments(data):
        failures.append(f"{name}: comments differ after formatting")
    if meaning(data, tmp) != meaning(once, tmp):
        failures.append(f"{name}: --emit ir differs after formatting")
    if must_be_formatted and once != data:
        failures.append(f"{name}: not formatted (run `sdfc fmt -w`)")


def snippets(path):
    text = open(path, encoding="utf-8").read()
    # A snippet after `<!-- fmt: off ... -->` shows unformatted text on purpose.
    return [(m.group(2).encode(), m.group(1) is None)
            for m in re.finditer(r"(<!-- fmt: off[^>]*-->\n)?```sdf\n(.*?)```", text, re.S)]


with tempfile.TemporaryDirectory() as tmp:
    for path in sorted(glob.glob(os.path.join(root, "examples", "**", "*.sdf"), recursive=True)):
        check(os.path.relpath(path, root), open(path, "rb").read(), True, tmp)
    for doc in [os.path.join(root, "README.md")] + sorted(glob.glob(os.path.join(root, "docs", "*.md"))):
        for i, (snippet, formatted) in enumerate(snippets(doc)):
            check(f"{os.path.relpath(doc, root)} snippet {i + 1}", snippet, formatted, tmp)
    for path in sorted(glob.glob(os.path.join(root, "fuzz", "corpus", "*")) +
                       glob.glob(os.path.join(root, "fuzz", "regressions", "*.sdf"))):
        check(os.path.relpath(path, root), open(path, "rb").read(), False, tmp)

for f in failures:
    print("FAIL", f)
print(f"fmt_meaning: {checked} files formatted and compared, {skipped} with syntax errors skipped")
print(f"{checked - len(failures)} passed, {len(failures)} failed")
sys.exit(1 if failures else 0)
