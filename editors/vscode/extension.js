// The VS Code side of sdfc: starts `sdfc lsp` for .sdf files and adds two
// commands that run the compiler on the current file. All language features
// come from the server; this file only wires it up.
'use strict';
const path = require('path');
const { spawn } = require('child_process');
const vscode = require('vscode');
const { LanguageClient } = require('vscode-languageclient/node');

let client;

function sdfcPath() {
  return vscode.workspace.getConfiguration('sdfc').get('path') || 'sdfc';
}

function startClient(context) {
  const command = sdfcPath();
  const server = { command, args: ['lsp'], options: {} };
  client = new LanguageClient('sdfc', 'sdfc language server',
    { run: server, debug: server },
    { documentSelector: [{ scheme: 'file', language: 'sdf' }, { scheme: 'untitled', language: 'sdf' }] });
  client.start().catch((err) => {
    vscode.window.showErrorMessage(`Could not start '${command} lsp': ${err.message}. Set "sdfc.path".`);
  });
}

// The saved .sdf file of the active editor, or undefined (with a message).
async function currentScene() {
  const editor = vscode.window.activeTextEditor;
  if (!editor || editor.document.languageId !== 'sdf') {
    vscode.window.showWarningMessage('Open a .sdf file first.');
    return undefined;
  }
  if (editor.document.isUntitled) {
    vscode.window.showWarningMessage('Save the scene to a file first.');
    return undefined;
  }
  if (editor.document.isDirty) await editor.document.save();
  return editor.document.uri.fsPath;
}

function run(output, args, cwd) {
  return new Promise((resolve) => {
    output.appendLine(`$ ${sdfcPath()} ${args.join(' ')}`);
    const child = spawn(sdfcPath(), args, { cwd });
    child.stdout.on('data', (d) => output.append(d.toString()));
    child.stderr.on('data', (d) => output.append(d.toString()));
    child.on('error', (err) => { output.appendLine(err.message); resolve(-1); });
    child.on('close', (code) => resolve(code));
  });
}

function activate(context) {
  const output = vscode.window.createOutputChannel('sdfc');
  startClient(context);

  context.subscriptions.push(vscode.commands.registerCommand('sdfc.renderToImage', async () => {
    const scene = await currentScene();
    if (!scene) return;
    const image = scene.replace(/\.sdf$/, '') + '.png';
    const extra = vscode.workspace.getConfiguration('sdfc').get('render.arguments') || [];
    output.show(true);
    const code = await vscode.window.withProgress(
      { location: vscode.ProgressLocation.Notification, title: `sdfc: rendering ${path.basename(scene)}` },
      () => run(output, ['render', scene, '-o', image, '-q', ...extra], path.dirname(scene)));
    if (code === 0) {
      await vscode.commands.executeCommand('vscode.open', vscode.Uri.file(image), vscode.ViewColumn.Beside);
    } else {
      vscode.window.showErrorMessage(`sdfc render failed (exit ${code}); see the sdfc output.`);
    }
  }));

  context.subscriptions.push(vscode.commands.registerCommand('sdfc.openLiveView', async () => {
    const scene = await currentScene();
    if (!scene) return;
    output.show(true);
    // `sdfc view` opens its own window and re-renders when the file changes.
    run(output, ['view', scene], path.dirname(scene)).then((code) => {
      if (code !== 0) vscode.window.showErrorMessage(`sdfc view exited with ${code}; see the sdfc output.`);
    });
  }));

  context.subscriptions.push(vscode.commands.registerCommand('sdfc.restartServer', async () => {
    if (client) await client.stop();
    startClient(context);
  }));
}

function deactivate() {
  return client ? client.stop() : undefined;
}

module.exports = { activate, deactivate };
