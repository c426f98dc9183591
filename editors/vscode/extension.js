// A minimal client for the bgr language server: it runs the command of the `bgr.command`
// setting (by default `bgr lsp`) and talks LSP with it over stdin/stdout for bgr documents.
const vscode = require('vscode');
const { LanguageClient, TransportKind } = require('vscode-languageclient/node');

let client;

async function activate(context) {
  const [command, ...args] = vscode.workspace.getConfiguration('bgr').get('command', ['bgr', 'lsp']);
  const server = { command, args, transport: TransportKind.stdio };
  client = new LanguageClient(
    'bgr',
    'bgr language server',
    { run: server, debug: server },
    {
      documentSelector: [
        { scheme: 'file', language: 'bgr' },
        { scheme: 'untitled', language: 'bgr' },
      ],
    },
  );
  await client.start();
}

function deactivate() {
  return client ? client.stop() : undefined;
}

module.exports = { activate, deactivate };
