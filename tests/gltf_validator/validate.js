// Validate glTF/GLB files with the Khronos glTF validator; print one JSON report per line.
// Usage: node validate.js FILE...   (after `npm install` in this folder)
"use strict";
const fs = require("fs");
const path = require("path");
const validator = require("gltf-validator");

async function report(file) {
  const bytes = new Uint8Array(fs.readFileSync(file));
  const result = await validator.validateBytes(bytes, {
    uri: path.basename(file),
    maxIssues: 100,
    externalResourceFunction: () => Promise.reject(new Error("external resources are not used")),
  });
  const issues = result.issues;
  return {
    file,
    errors: issues.numErrors,
    warnings: issues.numWarnings,
    infos: issues.numInfos,
    hints: issues.numHints,
    messages: issues.messages.map((m) => ({
      code: m.code, severity: m.severity, pointer: m.pointer, message: m.message,
    })),
    extensionsUsed: result.info ? result.info.extensionsUsed || [] : [],
    totalTriangleCount: result.info ? result.info.totalTriangleCount : null,
  };
}

(async () => {
  for (const file of process.argv.slice(2)) {
    console.log(JSON.stringify(await report(file)));
  }
})().catch((e) => { console.error(String(e)); process.exit(2); });
