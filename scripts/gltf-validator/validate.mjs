#!/usr/bin/env node
// Validates glTF / GLB files with the Khronos glTF validator (npm package gltf-validator).
// Usage: node scripts/gltf-validator/validate.mjs FILE...
// Prints one summary line per file (errors, warnings, infos, hints) and every error and
// warning; exits 1 when any file has an error, 2 when the validator itself cannot run.
import { readFile } from 'node:fs/promises';
import path from 'node:path';
import { createRequire } from 'node:module';

const require = createRequire(import.meta.url);
let validator;
try {
  validator = require('gltf-validator');
} catch (e) {
  console.error(`validate.mjs: the gltf-validator package is not installed (${e.code ?? e.message}); run: npm install --prefix scripts/gltf-validator`);
  process.exit(2);
}

const files = process.argv.slice(2);
if (files.length === 0) {
  console.error('usage: node scripts/gltf-validator/validate.mjs FILE...');
  process.exit(2);
}

let failed = false;
for (const file of files) {
  const data = new Uint8Array(await readFile(file));
  const dir = path.dirname(file);
  const report = await validator.validateBytes(data, {
    uri: path.basename(file),
    maxIssues: 100,
    // External buffers and images are read next to the file.
    externalResourceFunction: (uri) => readFile(path.join(dir, decodeURIComponent(uri))).then((b) => new Uint8Array(b)),
  });
  const i = report.issues;
  console.log(`${file}: ${i.numErrors} errors, ${i.numWarnings} warnings, ${i.numInfos} infos, ${i.numHints} hints`);
  for (const m of i.messages) {
    if (m.severity <= 1) {
      console.log(`  ${m.severity === 0 ? 'error' : 'warning'} ${m.code} at ${m.pointer ?? ''}: ${m.message}`);
    }
  }
  if (i.numErrors > 0) failed = true;
}
process.exit(failed ? 1 : 0);
