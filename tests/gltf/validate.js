// Validates a .glb with the Khronos glTF validator; prints its report's issues and info as JSON.
// Exit 0 when the report has no errors, 1 when it has, 2 when the validator could not run.
const validator = require('gltf-validator');
const fs = require('fs');
const bytes = new Uint8Array(fs.readFileSync(process.argv[2]));
validator
  .validateBytes(bytes, { maxIssues: 200 })
  .then((r) => {
    console.log(JSON.stringify({ issues: r.issues, info: r.info }));
    process.exit(r.issues.numErrors > 0 ? 1 : 0);
  })
  .catch((e) => {
    console.error(String(e));
    process.exit(2);
  });
