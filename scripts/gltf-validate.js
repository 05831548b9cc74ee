// Validates glTF / GLB files with the Khronos glTF validator (npm `gltf-validator`) and prints,
// per file, its error count and the errors by code, as JSON. External resources are read
// beside each file. Used by scripts/lod-validate.sh.
const validator = require('gltf-validator');
const fs = require('fs');
const path = require('path');

(async () => {
  const out = {};
  for (const file of process.argv.slice(2)) {
    const read = (uri) => new Promise((resolve, reject) => {
      fs.readFile(path.join(path.dirname(file), decodeURIComponent(uri)),
        (err, data) => (err ? reject(err.toString()) : resolve(new Uint8Array(data))));
    });
    try {
      const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(file)), {
        uri: path.basename(file),
        maxIssues: 0,
        externalResourceFunction: read,
      });
      const codes = {};
      for (const m of report.issues.messages) {
        if (m.severity === 0) codes[m.code] = (codes[m.code] || 0) + 1;
      }
      out[file] = { errors: report.issues.numErrors, codes };
    } catch (e) {
      out[file] = { failed: String(e) };
    }
  }
  console.log(JSON.stringify(out, null, 1));
})();
