#!/usr/bin/env bash
# Issue 29 "Messages" and issue 28's error flood: what the command line says
# to a mistake, and with which exit code (0 ok, 1 scene errors, 2 usage,
# 4 files). No case needs a device. Usage: cli_messages_test.sh <sdfc>
set -uo pipefail
sdfc=$1
root=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d "${TMPDIR:-/tmp}/sdfc messages.XXXXXX")  # a space in every path
trap 'rm -rf "$work"' EXIT
failures=0

. "$root/tests/cli_expect.sh"

scene=$root/examples/morph.sdf
printf 'scene { union(smooth: 0.1) { sphere(radius: 1) box(size: 1) } }\n' >"$work/smooth.sdf"

# Mistyped commands and options get a suggestion; every message starts "sdfc: error:".
expect 2 "^sdfc: error: unknown command 'rendr'; did you mean 'render'\?" -- "$sdfc" rendr "$scene"
expect 2 "^sdfc: error: unknown command 'sbmit'; did you mean 'submit'\?" -- "$sdfc" farm sbmit "$scene"
expect 2 "^sdfc: error: .* needs a command: check, compile, render" -- "$sdfc"
expect 2 "^sdfc: error: unknown option '--sppp' for 'sdfc render'; did you mean '--spp'\?" -- "$sdfc" render "$scene" --sppp 3 -o "$work/x.png"
expect 2 "^sdfc: error: unknown option '--daignostics-format' for 'sdfc check'; did you mean '--diagnostics-format'\?" -- "$sdfc" check "$scene" --daignostics-format=json
expect 2 "^sdfc: error: Could not convert: --time = abc; see 'sdfc render --help'" -- "$sdfc" render "$scene" --time abc -o "$work/x.png"
expect 2 "^sdfc: error: --spp: expects a whole number from 1 to 1048576, got '0'" -- "$sdfc" render "$scene" --spp 0 -o "$work/x.png"
# A file type sdfc cannot write is a usage error (2), as documented; a missing
# folder is a file error (4) that says so (sdfc creates no folders).
expect 2 "^sdfc: error: -o '.*x.jpg': unknown image extension '.jpg'" -- "$sdfc" render "$scene" -o "$work/x.jpg"
expect 4 "^sdfc: error: cannot write '$work/frames/f.png': the folder '$work/frames' does not exist \(sdfc creates no folders" -- "$sdfc" render "$scene" -o "$work/frames/f.png"

# eval --material names the material a shape renders with: a shape without
# `material:` takes the file's first (it printed '-'; and the renderer took the
# first one checked, blue here, used first); '-' only when the file defines none.
printf 'let red = diffuse(albedo: [1, 0, 0])\nlet blue = diffuse(albedo: [0, 0, 1])\nscene { translate([-5, 0, 0]) { sphere(radius: 1, material: blue) } sphere(radius: 1) translate([5, 0, 0]) { sphere(radius: 1, material: blue) } }\n' >"$work/mat.sdf"
got=$(printf '0 0 0\n5 0 0\n' | "$sdfc" eval "$work/mat.sdf" --material 2>/dev/null | awk '{print $2, $3, $4, $5}' | tr '\n' ';')
[ "$got" = "red 1 0 0;blue 0 0 1;" ] || fail "eval --material of a shape without material: got '$got'"
"$sdfc" compile "$work/mat.sdf" --emit glsl -o - | grep -A3 "^Material sdMaterial(int id)" | grep -q "^  return .*// red$" ||
  fail "the shader's default material is not the file's first"
# Material ids (the layers' `material`, --emit ir's) count in the file's order.
[ "$("$sdfc" compile "$work/mat.sdf" --emit ir -o - | grep -o '^material [0-9] [a-z]*' | tr '\n' ';')" = "material 0 red;material 1 blue;" ] ||
  fail "materials are not numbered in the file's order"
printf 'scene { sphere(radius: 1) }\n' >"$work/nomat.sdf"
got=$(printf '0 0 0\n' | "$sdfc" eval "$work/nomat.sdf" --material 2>/dev/null | awk '{print $2}')
[ "$got" = "-" ] || fail "eval --material with no material in the file: got '$got'"

# --version names the commit it was built from.
"$sdfc" --version >"$work/version" 2>&1 || fail "--version exits $?"
grep -Eq "^commit: ([0-9a-f]{12}(\+dirty)?|unknown \(not built from a git checkout\))$" "$work/version" ||
  { fail "--version names no commit:"; cat "$work/version" >&2; }
if git -C "$root" rev-parse HEAD >/dev/null 2>&1; then
  grep -q "^commit: $(git -C "$root" rev-parse --short=12 HEAD)" "$work/version" ||
    { fail "--version's commit is not HEAD's:"; cat "$work/version" >&2; }
fi

# Warnings have names, shown as [-Wname], and -Wno-name turns one off.
expect 0 "warning: smooth 'union' gives a distance bound.*\[-Wbound\]$" -- "$sdfc" check "$work/smooth.sdf"
expect 0 "" -- "$sdfc" check "$work/smooth.sdf" -Wno-bound
[ -s "$work/err" ] && { fail "-Wno-bound still printed:"; cat "$work/err" >&2; }
expect 1 "warning: smooth" -- "$sdfc" check "$work/smooth.sdf" -Werror
expect 0 "" -- "$sdfc" check "$work/smooth.sdf" -Wno-bound --Werror
expect 2 "^sdfc: error: -Wno-bund: no warning is named 'bund'; did you mean '-Wno-bound'\?" -- "$sdfc" check "$work/smooth.sdf" -Wno-bund
expect 0 "\"name\":\"bound\"" -- "$sdfc" check "$work/smooth.sdf" --diagnostics-format json

# JSON diagnostics come in source order, as the text ones do.
printf 'scene { sphere(radius: -1) }\nlet a = b\n' >"$work/order.sdf"
"$sdfc" check "$work/order.sdf" --diagnostics-format json 2>"$work/json"
python3 - "$work/json" <<'PY' || fail "JSON diagnostics out of source order: $(cat "$work/json")"
import json, sys
lines = [d["line"] for d in json.load(open(sys.argv[1]))]
sys.exit(0 if len(lines) >= 2 and lines == sorted(lines) else 1)
PY

# JSON diagnostics keep their notes (an import cycle's chain was dropped).
printf 'import "cb.sdf"\nlet a = sphere(radius: 1)\n' >"$work/ca.sdf"
printf 'import "ca.sdf"\nlet b = sphere(radius: 1)\n' >"$work/cb.sdf"
printf 'import "ca.sdf"\nscene { a }\n' >"$work/cycle.sdf"
"$sdfc" check "$work/cycle.sdf" --diagnostics-format json 2>"$work/json"
python3 - "$work/json" <<'PY' || fail "JSON diagnostics without their notes: $(cat "$work/json")"
import json, sys
d = json.load(open(sys.argv[1]))
cycle = [x for x in d if x["message"].startswith("import cycle")]
notes = cycle[0].get("notes", []) if cycle else []
sys.exit(0 if len(notes) == 2 and all(n["line"] == 1 and n["message"].endswith("is imported here") and
                                      n["severity"] == "note" for n in notes) else 1)
PY

# A CSV that cannot be read: why, and the path that was tried.
printf 'scene { instances(positions: file("nope.csv")) { sphere(radius: 0.1) } }\n' >"$work/csv.sdf"
expect 1 "error: cannot read 'nope.csv': No such file or directory \(looked for '$work/nope.csv'\)" -- "$sdfc" check "$work/csv.sdf"

# --frames means frame numbers A-B at --fps everywhere; the old times form
# is refused with the spelling that means the same.
expect 2 "--frames takes frame numbers A-B at --fps .*write --frames 0-20 --fps 10" -- "$sdfc" render "$scene" --frames 0-2:0.1 -o "$work/x.png"
expect 2 "gives 200001 frames; at most 100000" -- "$sdfc" render "$scene" --frames 0-200000 -o "$work/x.png"
expect 2 "--frames expects A-B" -- "$sdfc" render "$scene" --frames 3-1 -o "$work/x.png"

# The error flood of issue 28: 100,000 stray braces, or 3,000 errors on
# one line, print a few kilobytes, not hundreds of megabytes.
python3 -c "print('scene '+'{'*100000+'}'*100000)" >"$work/braces.sdf"
expect 1 "expected an expression, found '\{'" -- "$sdfc" check "$work/braces.sdf"
[ "$(wc -c <"$work/err")" -lt 4000 ] || fail "100k braces printed $(wc -c <"$work/err") bytes"
python3 -c "print('scene { ' + ' '.join(['sphere(radius: -1)'] * 3000) + ' }')" >"$work/many.sdf"
expect 1 "^sdfc: note: stopped after 20 errors; 2980 more errors not shown \(--error-limit 0 shows them all\)" -- "$sdfc" check "$work/many.sdf"
[ "$(grep -c ': error: ' "$work/err")" -eq 20 ] || fail "the error limit printed $(grep -c ': error: ' "$work/err") errors"
[ "$(wc -c <"$work/err")" -lt 20000 ] || fail "20 errors on a long line printed $(wc -c <"$work/err") bytes"
grep -Eq '^\.\.\..*\.\.\.$' "$work/err" || fail "a long line is not shown as a window"
expect 1 "" -- "$sdfc" check "$work/many.sdf" --error-limit 3
[ "$(grep -c ': error: ' "$work/err")" -eq 3 ] || fail "--error-limit 3 printed $(grep -c ': error: ' "$work/err") errors"
"$sdfc" check "$work/many.sdf" --error-limit 0 --diagnostics-format json 2>"$work/all.json"
python3 -c "import json,sys; n=len(json.load(open(sys.argv[1]))); sys.exit(0 if n == 3000 else 1)" "$work/all.json" ||
  fail "--error-limit 0 did not give all 3000 errors"

if [ "$failures" -ne 0 ]; then
  echo "$failures failure(s)" >&2
  exit 1
fi
echo "all passed"
