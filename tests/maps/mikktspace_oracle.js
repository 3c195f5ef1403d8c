// MikkTSpace oracle: runs the npm package `mikktspace` (a WebAssembly build
// of the reference implementation; installed into BUILD/oracles by
// scripts/install-test-oracles.sh) on unindexed triangles.
// IN holds float32 per corner: position xyz, normal xyz, uv; OUT gets
// float32 xyzw per corner as the package returns them (its sign, for UVs
// with v up). Exits 77 when the package is not installed.
// usage: node mikktspace_oracle.js ORACLES_DIR IN OUT
'use strict';
const fs = require('fs');
const path = require('path');

let mikk;
try {
    mikk = require(path.resolve(process.argv[2], 'node_modules', 'mikktspace'));
} catch (e) {
    console.log('mikktspace is not installed in ' + process.argv[2]);
    process.exit(77);
}
const buf = fs.readFileSync(process.argv[3]);
const all = new Float32Array(buf.buffer, buf.byteOffset, buf.length / 4);
const n = all.length / 8;
const pos = new Float32Array(3 * n), nrm = new Float32Array(3 * n), uv = new Float32Array(2 * n);
for (let i = 0; i < n; i++) {
    for (let k = 0; k < 3; k++) {
        pos[3 * i + k] = all[8 * i + k];
        nrm[3 * i + k] = all[8 * i + 3 + k];
    }
    uv[2 * i] = all[8 * i + 6];
    uv[2 * i + 1] = all[8 * i + 7];
}
const t = mikk.generateTangents(pos, nrm, uv);
fs.writeFileSync(process.argv[4], Buffer.from(t.buffer, t.byteOffset, t.byteLength));
