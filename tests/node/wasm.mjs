// Shared helpers for the node tests: the nodejs wasm build and the test meshes.
import fs from 'node:fs';
import { createRequire } from 'node:module';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath, pathToFileURL } from 'node:url';
import * as esbuild from 'esbuild';

export const root = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '../..');
export const sharedMeshes = path.resolve(root, '../shared/meshes');
export const committedFandisk = path.join(root, 'web/public/samples/fandisk.obj');

const pkg = path.join(root, 'build/pkg-node/conemap.js');

/** The wasm module built for node (CommonJS glue from wasm-bindgen --target nodejs). */
export function loadWasm() {
  if (!fs.existsSync(pkg)) throw new Error(`${pkg} missing: run \`npm run build\` first`);
  return createRequire(import.meta.url)(pkg);
}

let bundles = null;

/** The page's module web/src/NAME.ts, bundled by esbuild and imported (its own code, without a browser). */
export async function loadPageModule(name) {
  bundles ??= fs.mkdtempSync(path.join(os.tmpdir(), 'conemap-page-modules-'));
  const file = path.join(bundles, `${name}.mjs`);
  await esbuild.build({ entryPoints: [path.join(root, 'web/src', `${name}.ts`)], bundle: true, format: 'esm', platform: 'neutral', outfile: file, logLevel: 'silent' });
  return import(pathToFileURL(file).href);
}

/** Expected topology from ../shared/meshes/README.md. */
export const EXPECTED = {
  fandisk: { vertices: 6475, faces: 12946, euler_characteristic: 2 },
  spot: { vertices: 2930, faces: 5856, euler_characteristic: 2 },
  woody: { vertices: 694, faces: 1267, euler_characteristic: 1 },
  alligator: { vertices: 3208, faces: 5981, euler_characteristic: 1 },
};

/** Path of ../shared/meshes/NAME.obj; throws when absent (a checkout without
 *  the shared fixtures must fail, not pass by skipping). */
export const sharedMesh = (name) => {
  const p = path.join(sharedMeshes, `${name}.obj`);
  if (!fs.existsSync(p)) throw new Error(`fixture ${p} not found: the shared meshes must sit beside the checkout`);
  return p;
};

/** Imports files given as paths or {name, bytes}; the first is the mesh. */
export function importFiles(wasm, files) {
  return wasm.import_mesh(files.map((f) => (typeof f === 'string'
    ? { name: path.basename(f), bytes: new Uint8Array(fs.readFileSync(f)) }
    : { name: f.name, bytes: new Uint8Array(f.bytes) })));
}

/**
 * A needle as OBJ text: a hexagonal pyramid of height `h` over a unit hexagon,
 * the base fanned from its centre. Its rim (the hexagon) has dihedral angles
 * of about 92°, the sides meet at about 60°. With the rim as features
 * (sharp > 75°) it cannot be aligned for h = 25 .. 40: the rim encloses
 * nearly 2 pi of curvature at the apex, which would need a cone of angle 0.
 * Side faces start at the rim, so that the refinement renumbers the apex.
 */
export function needleObj(h) {
  const lines = [`v 0 0 ${h}`];
  for (let i = 0; i < 6; i++) lines.push(`v ${Math.cos((Math.PI * i) / 3)} ${Math.sin((Math.PI * i) / 3)} 0`);
  lines.push('v 0 0 0');
  for (let i = 0; i < 6; i++) {
    const a = 2 + i;
    const b = 2 + ((i + 1) % 6);
    lines.push(`f ${a} ${b} 1`, `f 8 ${b} ${a}`);
  }
  return `${lines.join('\n')}\n`;
}
