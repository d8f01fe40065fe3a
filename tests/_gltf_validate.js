// Validate one glTF/GLB file with the Khronos glTF-Validator (npm package "gltf-validator")
// and print its JSON report on stdout.
// Usage: node tests/_gltf_validate.js FILE.glb
// The package is found via NODE_PATH (the tests set it to <repo>/.cache/node/node_modules).
"use strict";
const fs = require("fs");
const path = require("path");
const validator = require("gltf-validator");

const file = process.argv[2];
if (!file) {
  console.error("usage: node _gltf_validate.js FILE.glb");
  process.exit(2);
}
const bytes = new Uint8Array(fs.readFileSync(file));
validator
  .validateBytes(bytes, {
    uri: path.basename(file),
    maxIssues: 0, // no limit
    externalResourceFunction: (uri) =>
      new Promise((resolve, reject) => {
        fs.readFile(path.join(path.dirname(file), decodeURIComponent(uri)), (err, data) =>
          err ? reject(err.toString()) : resolve(new Uint8Array(data)));
      }),
  })
  .then((report) => {
    process.stdout.write(JSON.stringify(report, null, 1));
  })
  .catch((err) => {
    console.error("validation failed:", err);
    process.exit(1);
  });
