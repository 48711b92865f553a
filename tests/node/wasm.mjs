// Shared helpers for the node tests: the nodejs wasm build and the test meshes.
import fs from 'node:fs';
import { createRequire } from 'node:module';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

export const root = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '../..');
export const sharedMeshes = path.resolve(root, '../shared/meshes');
export const committedFandisk = path.join(root, 'web/public/samples/fandisk.obj');

const pkg = path.join(root, 'build/pkg-node/conemap.js');

/** The wasm module built for node (CommonJS glue from wasm-bindgen --target nodejs). */
export function loadWasm() {
  if (!fs.existsSync(pkg)) throw new Error(`${pkg} missing: run \`npm run build\` first`);
  return createRequire(import.meta.url)(pkg);
}

/** Expected topology from ../shared/meshes/README.md. */
export const EXPECTED = {
  fandisk: { vertices: 6475, faces: 12946, euler_characteristic: 2 },
  spot: { vertices: 2930, faces: 5856, euler_characteristic: 2 },
  woody: { vertices: 694, faces: 1267, euler_characteristic: 1 },
  alligator: { vertices: 3208, faces: 5981, euler_characteristic: 1 },
};

export const sharedMesh = (name) => {
  const p = path.join(sharedMeshes, `${name}.obj`);
  return fs.existsSync(p) ? p : null;
};

/** Imports files given as paths or {name, bytes}; the first is the mesh. */
export function importFiles(wasm, files) {
  return wasm.import_mesh(files.map((f) => (typeof f === 'string'
    ? { name: path.basename(f), bytes: new Uint8Array(fs.readFileSync(f)) }
    : { name: f.name, bytes: new Uint8Array(f.bytes) })));
}
