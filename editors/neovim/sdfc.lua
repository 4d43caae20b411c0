-- sdfc's language server for *.sdf files, for Neovim 0.7 and later (Debian 12
-- ships 0.7.2, which has neither vim.lsp.start nor filetype.lua by default).
-- Use it from init.lua with `dofile("/path/to/sdfc/editors/neovim/sdfc.lua")`,
-- or copy it there. Set vim.g.sdfc_path first if sdfc is not on PATH.
vim.api.nvim_create_autocmd({ "BufRead", "BufNewFile" }, {
  pattern = "*.sdf",
  callback = function() vim.bo.filetype = "sdf" end,
})

vim.api.nvim_create_autocmd("FileType", {
  pattern = "sdf",
  callback = function(args)
    -- One server for every .sdf buffer: it keeps each open file apart.
    local id = vim.g.sdfc_lsp_client
    if not id or not vim.lsp.get_client_by_id(id) then
      id = vim.lsp.start_client({
        name = "sdfc",
        cmd = { vim.g.sdfc_path or "sdfc", "lsp" },
        root_dir = vim.fn.fnamemodify(vim.api.nvim_buf_get_name(args.buf), ":p:h"),
      })
      vim.g.sdfc_lsp_client = id
    end
    if id then vim.lsp.buf_attach_client(args.buf, id) end
  end,
})
