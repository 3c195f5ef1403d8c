// Prints, for each primitive of a GLB (mesh order), its triangles' corner
// positions (rounded to 1e-5) and the attribute names, one line per
// primitive: two files with the same lines keep triangles in their order
// and the same attributes. Reads the JSON and binary chunk directly
// (glTF 2.0 spec, 4.4), TRIANGLES mode, float positions, no sparse.
// usage: node glb_triangles.js FILE [IGNORED_ATTRIBUTE...]
'use strict';
const fs = require('fs');
const b = fs.readFileSync(process.argv[2]);
const ignore = new Set(process.argv.slice(3));
const jlen = b.readUInt32LE(12);
const g = JSON.parse(b.toString('utf8', 20, 20 + jlen));
const bin = b.subarray(20 + jlen + 8);
const comps = { SCALAR: 1, VEC2: 2, VEC3: 3, VEC4: 4 };
function read(ai) {
    const a = g.accessors[ai], v = g.bufferViews[a.bufferView];
    const n = comps[a.type], size = { 5126: 4, 5125: 4, 5123: 2, 5121: 1 }[a.componentType];
    const stride = v.byteStride || n * size, base = (v.byteOffset || 0) + (a.byteOffset || 0);
    const out = [];
    for (let i = 0; i < a.count; i++) {
        const e = [];
        for (let c = 0; c < n; c++) {
            const o = base + i * stride + c * size;
            e.push(a.componentType === 5126 ? bin.readFloatLE(o) : size === 4 ? bin.readUInt32LE(o)
                   : size === 2 ? bin.readUInt16LE(o) : bin.readUInt8(o));
        }
        out.push(e);
    }
    return out;
}
for (const m of g.meshes)
    for (const p of m.primitives) {
        const pos = read(p.attributes.POSITION);
        const idx = p.indices !== undefined ? read(p.indices).map((e) => e[0]) : pos.map((_, i) => i);
        const names = Object.keys(p.attributes).filter((k) => !ignore.has(k)).sort();
        const tris = idx.map((i) => pos[i].map((x) => Math.round(x * 1e5)).join(',')).join(' ');
        console.log(names.join(',') + ' | ' + tris);
    }
