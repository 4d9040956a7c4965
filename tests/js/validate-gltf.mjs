// Validates GLB/glTF files with the Khronos glTF validator. Prints one line per file with the
// error/warning/info counts and every error; exits 1 if any file has an error or none was given.
import { readFile } from 'node:fs/promises';
import validator from 'gltf-validator';

const files = process.argv.slice(2);
if (files.length === 0) {
  console.error('usage: node validate-gltf.mjs FILE...');
  process.exit(1);
}
let failed = 0;
for (const file of files) {
  const bytes = new Uint8Array(await readFile(file));
  const report = await validator.validateBytes(bytes, {
    uri: file,
    maxIssues: 1000,
    // External resources are not allowed: our GLBs are self-contained.
    externalResourceFunction: (uri) => Promise.reject(new Error(`external resource ${uri}`)),
  });
  const { numErrors, numWarnings, numInfos } = report.issues;
  console.log(`${file}: ${numErrors} errors, ${numWarnings} warnings, ${numInfos} infos`);
  for (const m of report.issues.messages) {
    if (m.severity === 0 || process.env.VERBOSE) console.log(`  [${m.severity}] ${m.code} ${m.pointer ?? ''}: ${m.message}`);
  }
  if (numErrors > 0) failed++;
}
if (failed) {
  console.error(`${failed} of ${files.length} files have errors`);
  process.exit(1);
}
