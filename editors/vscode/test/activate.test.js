// Loads extension.js with stand-ins for the `vscode` API and the language
// client (neither exists outside VS Code), then checks what activation
// registers and, when SDFC names a built sdfc, runs "render to image" for real.
// Run: node --test test/   (SDFC=/path/to/sdfc for the render check)
'use strict';
const test = require('node:test');
const assert = require('node:assert');
const fs = require('fs');
const os = require('os');
const path = require('path');
const Module = require('module');

const registered = {};
const clients = [];
const opened = [];
const messages = [];
const settings = { path: process.env.SDFC || 'sdfc', 'render.arguments': ['--spp', '1', '--size', '16x12'] };
let activeEditor;

const vscode = {
  window: {
    createOutputChannel: () => ({ append() {}, appendLine() {}, show() {} }),
    showErrorMessage: (m) => messages.push(['error', m]),
    showWarningMessage: (m) => messages.push(['warning', m]),
    withProgress: (_options, task) => task(),
    get activeTextEditor() { return activeEditor; },
  },
  workspace: { getConfiguration: () => ({ get: (key) => settings[key] }) },
  commands: {
    registerCommand: (name, fn) => { registered[name] = fn; return { dispose() {} }; },
    executeCommand: async (name, ...args) => { opened.push([name, ...args]); },
  },
  Uri: { file: (p) => ({ fsPath: p }) },
  ViewColumn: { Beside: -2 },
  ProgressLocation: { Notification: 15 },
};

class LanguageClient {
  constructor(id, name, serverOptions, clientOptions) {
    Object.assign(this, { id, name, serverOptions, clientOptions });
    clients.push(this);
  }
  start() { return Promise.resolve(); }
  stop() { return Promise.resolve(); }
}

const realLoad = Module._load;
Module._load = function (request, ...rest) {
  if (request === 'vscode') return vscode;
  if (request === 'vscode-languageclient/node') return { LanguageClient };
  return realLoad.call(this, request, ...rest);
};
const extension = require('../extension.js');

test('activation starts `sdfc lsp` for .sdf documents and registers the commands', () => {
  extension.activate({ subscriptions: [] });
  assert.strictEqual(clients.length, 1);
  assert.deepStrictEqual(clients[0].serverOptions.run.args, ['lsp']);
  assert.strictEqual(clients[0].serverOptions.run.command, settings.path);
  assert.ok(clients[0].clientOptions.documentSelector.some((s) => s.language === 'sdf'));
  for (const c of ['sdfc.renderToImage', 'sdfc.openLiveView', 'sdfc.restartServer']) assert.ok(registered[c], c);
  const manifest = require('../package.json');
  const declared = manifest.contributes.commands.map((c) => c.command).sort();
  assert.deepStrictEqual(declared, Object.keys(registered).sort());
});

test('render to image without a .sdf editor only warns', async () => {
  activeEditor = undefined;
  await registered['sdfc.renderToImage']();
  assert.deepStrictEqual(messages.pop(), ['warning', 'Open a .sdf file first.']);
});

test('render to image writes a PNG beside the scene and opens it', { skip: !process.env.SDFC }, async () => {
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'sdfc-vscode-'));
  const scene = path.join(dir, 'ball.sdf');
  fs.writeFileSync(scene, 'scene { sphere(radius: 1) }\n');
  activeEditor = { document: { languageId: 'sdf', isUntitled: false, isDirty: false, uri: { fsPath: scene } } };
  await registered['sdfc.renderToImage']();
  const png = path.join(dir, 'ball.png');
  assert.ok(fs.existsSync(png), JSON.stringify(messages));
  assert.deepStrictEqual(fs.readFileSync(png).subarray(1, 4).toString(), 'PNG');
  assert.strictEqual(opened.at(-1)[0], 'vscode.open');
  assert.strictEqual(opened.at(-1)[1].fsPath, png);
  fs.rmSync(dir, { recursive: true });
});
