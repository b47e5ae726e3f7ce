#!/usr/bin/env node
// Shows a lightmapped glTF written by `radiosity export --lightmap-atlas DIR` as a game
// engine would: three.js in headless Chromium (software WebGL), emitters at their emissive
// radiance, every other material unlit and lit by the lightmap alone (MeshBasicMaterial: albedo x lightMap, the lightmap being the linear
// irradiance of DIR/lightmap.exr on TEXCOORD_1, times 1/pi), ACES tone mapping at the
// exposure the PNG was made with. Saves the picture.
//
// Usage: node scripts/lightmap-view/view.mjs DIR/lightmapped.gltf OUT.png
//          [--camera x,y,z] [--target x,y,z] [--fov degrees] [--size WxH] [--ev stops] [--png]
// --png: the tone-mapped PNG embedded in the glTF instead of the EXR (no tone mapping then).
// Needs: npm ci --prefix scripts/lightmap-view, and Chromium (Debian: apt-get install chromium).
import http from 'node:http';
import { readFile, writeFile } from 'node:fs/promises';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';

const here = path.dirname(fileURLToPath(import.meta.url));
const args = process.argv.slice(2);
if (args.length < 2) {
  console.error('usage: node view.mjs DIR/lightmapped.gltf OUT.png [--camera x,y,z] [--target x,y,z] [--fov deg] [--size WxH] [--ev stops]');
  process.exit(2);
}
const [gltfPath, outPath] = args;
const option = (name) => {
  const i = args.indexOf(name);
  return i >= 0 ? args[i + 1] : undefined;
};
const vector = (text) => (text ? text.split(',').map(Number) : null);
const [width, height] = (option('--size') ?? '960x540').split('x').map(Number);
const settings = {
  camera: vector(option('--camera')),
  target: vector(option('--target')),
  fov: Number(option('--fov') ?? 60),
  ev: option('--ev') === undefined ? null : Number(option('--ev')),
  png: args.includes('--png'),
  width,
  height,
  model: '/model/' + encodeURIComponent(path.basename(gltfPath)),
  hdr: '/model/lightmap.exr',
};

const page = `<!doctype html><html><body style="margin:0">
<script type="importmap">{"imports":{"three":"/three/build/three.module.js","three/addons/":"/three/examples/jsm/"}}</script>
<script type="module">
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { EXRLoader } from 'three/addons/loaders/EXRLoader.js';
const s = ${JSON.stringify(settings)};
try {
  const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
  renderer.setSize(s.width, s.height);
  renderer.toneMapping = THREE.ACESFilmicToneMapping;
  document.body.appendChild(renderer.domElement);
  const gltf = await new GLTFLoader().loadAsync(s.model);
  const info = gltf.parser.json.asset.extras.radiosity_lightmap;
  const lightmap = s.png
    ? await gltf.parser.getDependency('texture', info.texture)
    : await new EXRLoader().loadAsync(s.hdr);
  lightmap.channel = info.texCoord;
  // The EXR's first row is its top, where glTF's v = 0 is; three's EXRLoader puts it last.
  if (!s.png) lightmap.flipY = true;
  lightmap.colorSpace = s.png ? THREE.SRGBColorSpace : THREE.LinearSRGBColorSpace;
  lightmap.needsUpdate = true;
  if (s.png) {
    renderer.toneMapping = THREE.NoToneMapping;
  }
  const ev = s.ev ?? info.png_exposure_ev;
  renderer.toneMappingExposure = s.png ? 1 : Math.pow(2, ev);
  const scene = gltf.scene;
  scene.traverse((o) => {
    if (!o.isMesh) return;
    const m = o.material;
    // Irradiance E on a surface of albedo rho shows rho E / pi; radiosity B (the albedo
    // already in it) shows B / pi on white.
    const irradiance = info.quantity === 'irradiance';
    if (m.emissive && m.emissiveIntensity * Math.max(m.emissive.r, m.emissive.g, m.emissive.b) > 0) {
      // An emitter shows its own radiance: its emission M (factor x strength) over pi.
      o.material = new THREE.MeshBasicMaterial({
        color: m.emissive.clone().multiplyScalar(m.emissiveIntensity / Math.PI),
      });
      return;
    }
    o.material = new THREE.MeshBasicMaterial({
      color: irradiance ? m.color : new THREE.Color(1, 1, 1), map: irradiance ? m.map : null,
      lightMap: lightmap, lightMapIntensity: s.png ? 1 : 1 / Math.PI,
    });
  });
  const box = new THREE.Box3().setFromObject(scene);
  const size = box.getSize(new THREE.Vector3());
  const centre = box.getCenter(new THREE.Vector3());
  const camera = new THREE.PerspectiveCamera(s.fov, s.width / s.height, size.length() * 1e-4, size.length() * 4);
  if (s.camera) camera.position.set(...s.camera);
  else camera.position.set(centre.x, centre.y, centre.z + size.z * 0.45);
  camera.lookAt(...(s.target ?? centre.toArray()));
  renderer.render(scene, camera);
  window.done = 'ok';
} catch (e) {
  window.done = 'error: ' + (e && e.stack ? e.stack : e);
}
</script></body></html>`;

const types = { '.js': 'text/javascript', '.gltf': 'model/gltf+json', '.exr': 'image/x-exr', '.png': 'image/png' };
const server = http.createServer(async (req, res) => {
  const url = decodeURIComponent(req.url.split('?')[0]);
  let file;
  if (url === '/') {
    res.writeHead(200, { 'content-type': 'text/html' });
    res.end(page);
    return;
  } else if (url.startsWith('/three/')) {
    file = path.join(here, 'node_modules/three', url.slice('/three/'.length));
  } else if (url.startsWith('/model/')) {
    file = path.join(path.dirname(gltfPath), url.slice('/model/'.length));
  }
  try {
    const body = await readFile(file);
    res.writeHead(200, { 'content-type': types[path.extname(file)] ?? 'application/octet-stream' });
    res.end(body);
  } catch {
    res.writeHead(404);
    res.end();
  }
});
await new Promise((ok) => server.listen(0, '127.0.0.1', ok));
const port = server.address().port;
const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM ?? '/usr/bin/chromium',
  args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist',
    '--disable-quic', '--no-first-run', '--disable-background-networking', '--disable-component-update',
    '--disable-sync'],
});
try {
  const tab = await browser.newPage({ viewport: { width, height } });
  tab.on('console', (m) => console.error('page:', m.text()));
  await tab.goto(`http://127.0.0.1:${port}/`);
  await tab.waitForFunction(() => window.done, null, { timeout: 300_000 });
  const done = await tab.evaluate(() => window.done);
  if (done !== 'ok') throw new Error(done);
  const png = await tab.locator('canvas').screenshot();
  await writeFile(outPath, png);
  console.log(`wrote ${outPath}`);
} finally {
  await browser.close();
  server.close();
}
