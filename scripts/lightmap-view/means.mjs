#!/usr/bin/env node
// Per-object means of a lightmap atlas, read as an engine reads it: the glTF written by
// `radiosity export --lightmap-atlas DIR` through glTF-Transform (a glTF reader this project
// did not write), its lightmap EXR through three.js's EXRLoader, the texels sampled
// bilinearly at its texture coordinate set (TEXCOORD_1, or the one the file names) over a lattice of points on every triangle, weighted by area.
// Prints one JSON object: mesh name -> [r, g, b].
//
// Usage: node scripts/lightmap-view/means.mjs DIR/lightmapped.gltf
// Needs: npm ci --prefix scripts/lightmap-view
import { readFile } from 'node:fs/promises';
import path from 'node:path';
import { NodeIO } from '@gltf-transform/core';
import { EXRLoader } from 'three/examples/jsm/loaders/EXRLoader.js';
import { FloatType } from 'three';

const [gltfPath] = process.argv.slice(2);
if (!gltfPath) {
  console.error('usage: node means.mjs DIR/lightmapped.gltf');
  process.exit(2);
}
const json = JSON.parse(await readFile(gltfPath, 'utf8'));
const info = json.asset.extras.radiosity_lightmap;
const bytes = await readFile(path.join(path.dirname(gltfPath), info.hdr));
const loader = new EXRLoader();
loader.setDataType(FloatType);
const exr = loader.parse(bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength));
const { width, height, data } = exr;
const channels = data.length / (width * height);
// EXRLoader puts the image's top row last; glTF's v = 0 is the top.
const texel = (x, y, c) => {
  const xi = Math.min(width - 1, Math.max(0, x));
  const yi = Math.min(height - 1, Math.max(0, y));
  return data[((height - 1 - yi) * width + xi) * channels + c];
};
const bilinear = (u, v, c) => {
  const fx = u * width - 0.5;
  const fy = v * height - 0.5;
  const x0 = Math.floor(fx);
  const y0 = Math.floor(fy);
  const ax = fx - x0;
  const ay = fy - y0;
  return (1 - ax) * (1 - ay) * texel(x0, y0, c) + ax * (1 - ay) * texel(x0 + 1, y0, c)
    + (1 - ax) * ay * texel(x0, y0 + 1, c) + ax * ay * texel(x0 + 1, y0 + 1, c);
};

const doc = await new NodeIO().read(gltfPath);
const steps = 8;
const out = {};
for (const node of doc.getRoot().listNodes()) {
  const mesh = node.getMesh();
  if (!mesh) continue;
  const sum = [0, 0, 0];
  let area = 0;
  for (const prim of mesh.listPrimitives()) {
    const pos = prim.getAttribute('POSITION');
    const uv = prim.getAttribute(`TEXCOORD_${info.texCoord}`);
    const idx = prim.getIndices();
    for (let t = 0; t < idx.getCount(); t += 3) {
      const k = [idx.getScalar(t), idx.getScalar(t + 1), idx.getScalar(t + 2)];
      const p = k.map((i) => pos.getElement(i, []));
      const q = k.map((i) => uv.getElement(i, []));
      const e1 = p[1].map((x, c) => x - p[0][c]);
      const e2 = p[2].map((x, c) => x - p[0][c]);
      const cross = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]];
      const a = 0.5 * Math.hypot(...cross);
      // Centres of the steps x steps sub-triangles of equal area (upright ones and the rest).
      const points = [];
      for (let i = 0; i < steps; i++) {
        for (let j = 0; j < steps - i; j++) {
          points.push([(i + 1 / 3) / steps, (j + 1 / 3) / steps]);
          if (i + j < steps - 1) points.push([(i + 2 / 3) / steps, (j + 2 / 3) / steps]);
        }
      }
      for (const [b1, b2] of points) {
        const b0 = 1 - b1 - b2;
        const u = b0 * q[0][0] + b1 * q[1][0] + b2 * q[2][0];
        const v = b0 * q[0][1] + b1 * q[1][1] + b2 * q[2][1];
        for (let c = 0; c < 3; c++) sum[c] += bilinear(u, v, c) * a / points.length;
      }
      area += a;
    }
  }
  out[node.getName()] = sum.map((s) => s / area);
}
console.log(JSON.stringify(out));
