#!/usr/bin/env bash
# Packages the VS Code extension into editors/vscode/sdfc-sdf-<version>.vsix
# with the official packager (@vscode/vsce, pinned in package-lock.json).
# Needs node >= 20 and npm. The grammar is copied from grammar/ at package
# time, so there is one copy of it in the repository.
set -euo pipefail
cd "$(dirname "$0")"
mkdir -p syntaxes
cp ../../grammar/sdf.tmLanguage.json syntaxes/sdf.tmLanguage.json
npm ci --no-audit --no-fund --loglevel=error
node --test test/  # activation with stand-ins for the vscode API (SDFC=path/to/sdfc also renders)
node -e "require.resolve('vscode-languageclient/node')"  # the client the extension loads is installed
npx --no-install vsce package --skip-license --allow-missing-repository --no-update-package-json \
  --out "sdfc-sdf-$(node -p "require('./package.json').version").vsix" "$@"
# The package holds what the manifest names.
vsix="sdfc-sdf-$(node -p "require('./package.json').version").vsix"
python3 - "$vsix" <<'PY'
import json, sys, zipfile
names = set(zipfile.ZipFile(sys.argv[1]).namelist())
need = ["extension/extension.js", "extension/package.json", "extension/language-configuration.json",
        "extension/syntaxes/sdf.tmLanguage.json", "extension/node_modules/vscode-languageclient/node.js"]
missing = [n for n in need if n not in names]
manifest = json.loads(zipfile.ZipFile(sys.argv[1]).read("extension/package.json"))
assert manifest["contributes"]["grammars"][0]["scopeName"] == "source.sdf"
if missing:
    sys.exit(f"package.sh: {sys.argv[1]} lacks {missing}")
print(f"package.sh: {sys.argv[1]}: {len(names)} files, manifest and grammar present")
PY
