#!/usr/bin/env bash
# The language server in a real client: Debian 12's Neovim (0.7.2) with
# editors/neovim/sdfc.lua opens a scene in a folder with a space in its name,
# and must show sdfc's diagnostic at the right place, hover, and format.
set -euo pipefail
sdfc="$1"
root="$(cd "$(dirname "$0")/.." && pwd)"
command -v nvim >/dev/null || { echo "neovim_lsp: nvim is not installed (tools/setup.sh installs it)"; exit 1; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/my scenes"
scene="$work/my scenes/first try.sdf"
printf 'scene {\n    sphere(radus: 1)\n}\n' > "$scene"
cat > "$work/init.lua" <<LUA
vim.g.sdfc_path = "$sdfc"
dofile("$root/editors/neovim/sdfc.lua")
LUA
cat > "$work/check.lua" <<'LUA'
local out = {}
local ok = vim.wait(10000, function() return #vim.diagnostic.get(0) > 0 end, 50)
table.insert(out, "filetype " .. vim.bo.filetype)
for _, d in ipairs(vim.diagnostic.get(0)) do
  table.insert(out, string.format("diag %d:%d %s", d.lnum + 1, d.col + 1, d.message))
end
-- hover on 'sphere' (line 2, column 5)
local params = { textDocument = vim.lsp.util.make_text_document_params(),
                 position = { line = 1, character = 5 } }
local res = vim.lsp.buf_request_sync(0, "textDocument/hover", params, 5000) or {}
for _, r in pairs(res) do
  if r.result and r.result.contents then
    local c = r.result.contents
    local text = type(c) == "table" and (c.value or vim.inspect(c)) or tostring(c)
    table.insert(out, "hover " .. text:gsub("\n", " "):sub(1, 80))
  end
end
vim.lsp.buf.formatting_sync(nil, 5000)
table.insert(out, "formatted " .. table.concat(vim.api.nvim_buf_get_lines(0, 0, -1, false), "|"))
vim.fn.writefile(out, vim.env.SDFC_NVIM_OUT)
LUA
SDFC_NVIM_OUT="$work/out.txt" timeout 60 nvim --headless -u "$work/init.lua" "$scene" \
  -c "luafile $work/check.lua" -c 'qa!' > /dev/null 2>&1 || true
[ -f "$work/out.txt" ] || { echo "neovim_lsp: Neovim wrote nothing"; exit 1; }
cat "$work/out.txt"
fail=0
grep -qx 'filetype sdf' "$work/out.txt" || { echo "FAIL: filetype not set"; fail=1; }
grep -qF "diag 2:12 'sphere' has no parameter 'radus'; did you mean 'radius'?" "$work/out.txt" ||
  { echo "FAIL: diagnostic missing or misplaced"; fail=1; }
grep -q '^hover .*sphere' "$work/out.txt" || { echo "FAIL: no hover on sphere"; fail=1; }
grep -qxF 'formatted scene {|  sphere(radus: 1)|}' "$work/out.txt" || { echo "FAIL: formatting"; fail=1; }
exit $fail
