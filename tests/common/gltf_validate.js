// Runs the Khronos glTF-Validator (npm gltf-validator, a test oracle) on
// each file named: prints one line per file with its error and warning
// counts and every error, and exits 1 when any file has errors, 77 when
// the validator is not installed (the caller reports the test skipped).
// usage: node gltf_validate.js ORACLES_DIR FILE...
'use strict';
const fs = require('fs');
const path = require('path');

let validator;
try {
    validator = require(path.resolve(process.argv[2], 'node_modules', 'gltf-validator'));
} catch (e) {
    console.log('gltf-validator is not installed in ' + process.argv[2]);
    process.exit(77);
}

async function check(file) {
    const bytes = new Uint8Array(fs.readFileSync(file));
    const report = await validator.validateBytes(bytes, {
        uri: path.basename(file),
        maxIssues: 1000,
        externalResourceFunction: (uri) => new Promise((resolve, reject) => {
            fs.readFile(path.resolve(path.dirname(file), decodeURIComponent(uri)),
                        (err, data) => err ? reject(err.toString()) : resolve(new Uint8Array(data)));
        }),
    });
    const is = report.issues;
    console.log(`${file}: ${is.numErrors} errors, ${is.numWarnings} warnings, ${is.numInfos} infos`);
    for (const m of is.messages)
        if (m.severity === 0 || process.env.LX_VALIDATE_VERBOSE)
            console.log(`  ${m.severity === 0 ? 'error' : 'note'} ${m.code} ${m.pointer || ''}: ${m.message}`);
    return is.numErrors;
}

(async () => {
    let errors = 0;
    for (const f of process.argv.slice(3))
        errors += await check(f);
    process.exit(errors ? 1 : 0);
})().catch((e) => { console.log('validator failed: ' + e); process.exit(1); });
