// Validates glTF 2.0 files (.gltf or .glb) with the Khronos glTF validator.
//
//   node tests/gltf/validate.mjs NODE_MODULES_DIR FILE...
//
// NODE_MODULES_DIR is the folder that holds gltf-validator (tools/node/node_modules after
// `npm ci --prefix tools/node`; scripts/install-deps.sh does that). For each file prints one line
// "FILE: E errors, W warnings, I infos, H hints", then every message. Exits 0 if no file has an
// error, 1 if one has, 2 if the validator cannot be loaded or a file cannot be read.
import { createRequire } from "node:module";
import { readFile } from "node:fs/promises";
import path from "node:path";

const [modulesDir, ...files] = process.argv.slice(2);
if (!modulesDir || files.length === 0) {
  console.error("usage: node validate.mjs NODE_MODULES_DIR FILE...");
  process.exit(2);
}

let validator;
try {
  // Resolve the package from the given folder, not from this script's location.
  const require = createRequire(path.join(path.resolve(modulesDir), "..", "noop.js"));
  validator = require("gltf-validator");
} catch (error) {
  console.error(`cannot load gltf-validator from ${modulesDir}: ${error.message}; ` +
                "run scripts/install-deps.sh");
  process.exit(2);
}

const kSeverity = ["error", "warning", "info", "hint"];
let failed = false;
for (const file of files) {
  let bytes;
  try {
    bytes = new Uint8Array(await readFile(file));
  } catch (error) {
    console.error(`${file}: ${error.message}`);
    process.exit(2);
  }
  const report = await validator.validateBytes(bytes, {
    uri: path.basename(file),
    maxIssues: 0,  // unlimited
    writeTimestamp: false,
  });
  const issues = report.issues;
  console.log(`${file}: ${issues.numErrors} errors, ${issues.numWarnings} warnings, ` +
              `${issues.numInfos} infos, ${issues.numHints} hints (validator ${report.validatorVersion})`);
  for (const m of issues.messages) {
    console.log(`  ${kSeverity[m.severity] ?? m.severity} ${m.code} at ${m.pointer ?? "-"}: ${m.message}`);
  }
  if (issues.numErrors > 0) failed = true;
}
process.exit(failed ? 1 : 0);
