#!/usr/bin/env python3
"""`sdfc fmt` over every example, docs snippet and fuzz input (CTest: fmt_meaning).

For each file that parses:
  - formatting is idempotent: fmt(fmt(x)) == fmt(x);
  - formatting keeps every comment (the comment texts, in order, are the same);
  - formatting never changes meaning: `sdfc compile --emit ir` prints the same
    dump before and after (line numbers aside), or the same error messages;
and the examples and docs snippets are already formatted (`fmt --check`).
Then the command line itself: strings survive `fmt` and `fmt -w`, and `fmt -w`
writes through a symlink to its target, keeps hard links and the file's mode.
(tests/format_test.cpp checks the token contract on every token kind.)
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
    # at a lone CR; strings (on one line, no escapes) may hold "//" or "/*".
    return [m.group(1) for m in re.finditer(
        rb'"[^"\n]*"|(//[^\n\r]*?(?=[ \t]*(?:\r|\n|$))|/\*.*?\*/)', data, re.S) if m.group(1)]


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

def expect(name, condition):
    if not condition:
        failures.append(name)


# The command line: strings kept, and `fmt -w` keeps the file what it was.
messy = b'scene{instances(positions:file("my points.csv")){sphere(radius:0.1)}}\n'
tidy = b'scene { instances(positions: file("my points.csv")) { sphere(radius: 0.1) } }\n'
expect("fmt keeps a string", fmt(messy) == tidy)
with tempfile.TemporaryDirectory() as tmp:
    real = os.path.join(tmp, "real dir", "scene.sdf")
    os.makedirs(os.path.dirname(real))
    with open(real, "wb") as f:
        f.write(messy)
    os.chmod(real, 0o640)
    link = os.path.join(tmp, "link.sdf")
    os.symlink(os.path.join("real dir", "scene.sdf"), link)
    hard = os.path.join(tmp, "hard.sdf")
    os.link(real, hard)
    inode = os.stat(real).st_ino
    rc, _, err = run(["fmt", "-w", link])
    expect(f"fmt -w through a symlink exits 0 ({rc}, {err!r})", rc == 0)
    expect("fmt -w keeps the symlink a symlink", os.path.islink(link))
    expect("fmt -w writes the symlink's target", open(real, "rb").read() == tidy)
    expect("fmt -w keeps hard links (the other name sees the new text)", open(hard, "rb").read() == tidy)
    expect("fmt -w keeps the inode", os.stat(real).st_ino == inode and os.stat(real).st_nlink == 2)
    expect(f"fmt -w keeps the mode ({oct(os.stat(real).st_mode)})", os.stat(real).st_mode & 0o7777 == 0o640)
    # One link: through a temporary and a rename, with the mode kept.
    os.unlink(hard)
    with open(real, "wb") as f:
        f.write(messy)
    os.chmod(real, 0o600)
    rc, _, err = run(["fmt", "-w", real])
    expect(f"fmt -w exits 0 ({rc}, {err!r})", rc == 0 and open(real, "rb").read() == tidy)
    expect(f"fmt -w keeps mode 0600 ({oct(os.stat(real).st_mode)})", os.stat(real).st_mode & 0o7777 == 0o600)
    expect("fmt -w leaves no temporary", sorted(os.listdir(os.path.dirname(real))) == ["scene.sdf"])

# Imports (fmt crashed with exit 139 on any file with one): stdin, --check, -w.
messy_import = b'import   "parts.sdf"  as p\nimport "lib.sdf"\nscene{p.rook}\n'
tidy_import = b'import "parts.sdf" as p\nimport "lib.sdf"\nscene { p.rook }\n'
rc, out, err = run(["fmt"], messy_import)
expect(f"fmt with an import on stdin ({rc}, {err!r})", rc == 0 and out == tidy_import)
with tempfile.TemporaryDirectory() as tmp:
    path = os.path.join(tmp, "scene.sdf")
    with open(path, "wb") as f:
        f.write(tidy_import)
    rc, out, err = run(["fmt", "--check", path])
    expect(f"fmt --check on a formatted file with imports exits 0 ({rc}, {err!r})", rc == 0)
    with open(path, "wb") as f:
        f.write(messy_import)
    rc, out, err = run(["fmt", "--check", path])
    expect(f"fmt --check on an unformatted file with imports exits 1 ({rc}, {err!r})", rc == 1)
    rc, out, err = run(["fmt", "-w", path])
    expect(f"fmt -w with imports ({rc}, {err!r})", rc == 0 and open(path, "rb").read() == tidy_import)
    rc, out, err = run(["fmt", path])
    expect(f"fmt FILE with imports ({rc}, {err!r})", rc == 0 and out == tidy_import)

for f in failures:
    print("FAIL", f)
print(f"fmt_meaning: {checked} files formatted and compared, {skipped} with syntax errors skipped")
print(f"{checked - len(failures)} passed, {len(failures)} failed")
sys.exit(1 if failures else 0)
