// Builds glTF test fixtures from an OBJ with @gltf-transform/core.
//
//   node tests/node/make-gltf.mjs MESH.obj OUTDIR
//
// or, from a test:
//
//   import { makeGltfFixtures } from './make-gltf.mjs';
//   const written = await makeGltfFixtures(objPath, outDir);
//
// Writes, for <name>.obj:
//   <name>.glb             one node, one indexed TRIANGLES primitive
//   <name>-two-nodes.gltf  (+ <name>-two-nodes.bin) the faces split in two meshes
//                          under two nodes; the second sits under a node with a
//                          translation, rotation and non-uniform scale, and its
//                          vertices are pre-transformed by the inverse
//   <name>-strip.glb       one indexed TRIANGLE_STRIP primitive
//   <name>-nonindexed.glb  non-indexed TRIANGLES (three vertices per face)
//
// Every file holds exactly the OBJ's triangles (polygons fan-triangulated)
// with world-space positions bit-identical to the OBJ's f32 values, so an
// importer that welds by exact position sees the OBJ's connectivity.
//
// Returns [{ name, path, files, faces }]: `files` is the main file followed
// by its companions (the .bin), `faces` the expected triangle count (for the
// strip file, faces that repeat a vertex index are left out: see below).

import fs from 'node:fs';
import path from 'node:path';
import { pathToFileURL } from 'node:url';
import { Accessor, Document, NodeIO, Primitive } from '@gltf-transform/core';

/** Minimal OBJ reader: `v` and `f` lines, polygons fan-triangulated. */
export function parseObj(text) {
  const positions = [];
  const triangles = [];
  for (const raw of text.split('\n')) {
    const parts = raw.trim().split(/\s+/);
    if (parts[0] === 'v') {
      positions.push([Number(parts[1]), Number(parts[2]), Number(parts[3])]);
    } else if (parts[0] === 'f') {
      const count = positions.length;
      const idx = parts.slice(1).map((s) => {
        const i = parseInt(s.split('/')[0], 10);
        if (!Number.isInteger(i) || i === 0) throw new Error(`bad face index in: ${raw}`);
        return i < 0 ? count + i : i - 1;
      });
      for (let k = 1; k + 1 < idx.length; k++) triangles.push([idx[0], idx[k], idx[k + 1]]);
    }
  }
  return { positions: Float32Array.from(positions.flat()), triangles };
}

function indexArray(values, vertexCount) {
  return vertexCount < 65536 ? Uint16Array.from(values) : Uint32Array.from(values);
}

/** The sub-mesh of `tris` with its own compact vertex list (first-use order). */
function subMesh(positions, tris) {
  const map = new Map();
  const pos = [];
  const idx = [];
  for (const t of tris) {
    for (const v of t) {
      let n = map.get(v);
      if (n === undefined) {
        n = map.size;
        map.set(v, n);
        pos.push(positions[3 * v], positions[3 * v + 1], positions[3 * v + 2]);
      }
      idx.push(n);
    }
  }
  return { positions: Float32Array.from(pos), indices: idx };
}

/**
 * Strip encoding that keeps every triangle exactly: each triangle is its own
 * 3-index strip, joined to the previous one by repeating the last index and
 * the next first index (degenerate triangles readers drop). A triangle that
 * lands on an odd strip position is written (a, c, b), since the strip rule
 * swaps the last two corners there, giving back (a, b, c).
 */
export function stripIndices(tris) {
  const s = [];
  for (const [a, b, c] of tris) {
    if (s.length > 0) s.push(s[s.length - 1], a);
    if (s.length % 2 === 0) s.push(a, b, c);
    else s.push(a, c, b);
  }
  return s;
}

function newDocument() {
  const doc = new Document();
  const buffer = doc.createBuffer('buffer');
  const scene = doc.createScene('scene');
  doc.getRoot().setDefaultScene(scene);
  return { doc, buffer, scene };
}

function positionAccessor(doc, buffer, array) {
  return doc.createAccessor('POSITION').setType(Accessor.Type.VEC3).setArray(array).setBuffer(buffer);
}

function indexAccessor(doc, buffer, values, vertexCount) {
  return doc
    .createAccessor('indices')
    .setType(Accessor.Type.SCALAR)
    .setArray(indexArray(values, vertexCount))
    .setBuffer(buffer);
}

function singlePrimitive(name, positions, indices, mode) {
  const { doc, buffer, scene } = newDocument();
  const prim = doc.createPrimitive().setAttribute('POSITION', positionAccessor(doc, buffer, positions)).setMode(mode);
  if (indices) prim.setIndices(indexAccessor(doc, buffer, indices, positions.length / 3));
  const mesh = doc.createMesh(name).addPrimitive(prim);
  scene.addChild(doc.createNode(name).setMesh(mesh));
  return doc;
}

// The second half's node transform. Chosen so that every step is exact in
// floating point, which keeps the world positions bit-identical:
// a 120° rotation about (1,1,1) (quaternion ½(1,1,1,1): a cyclic permutation
// of the axes), power-of-two scales, and a translation that a child node
// cancels exactly.
const ROTATION = [0.5, 0.5, 0.5, 0.5]; // maps x→y, y→z, z→x
const SCALE = [2, 0.5, 4];
const TRANSLATION = [1.5, -2.25, 0.75];

/** (R·S)⁻¹ p = S⁻¹ · R⁻¹ p, with R⁻¹ mapping (x, y, z) → (y, z, x). */
function inverseLinear([x, y, z]) {
  const r = [y, z, x];
  return [r[0] / SCALE[0], r[1] / SCALE[1], r[2] / SCALE[2]];
}

function twoNodes(name, positions, triangles, binName) {
  const { doc, buffer, scene } = newDocument();
  buffer.setURI(binName);
  const half = Math.ceil(triangles.length / 2);
  const a = subMesh(positions, triangles.slice(0, half));
  const b = subMesh(positions, triangles.slice(half));
  // Half B's vertices, pre-transformed by the inverse of its world transform.
  const local = new Float32Array(b.positions.length);
  for (let i = 0; i < b.positions.length; i += 3) {
    local.set(inverseLinear([b.positions[i], b.positions[i + 1], b.positions[i + 2]]), i);
  }
  const mesh = (label, pos, idx) =>
    doc
      .createMesh(label)
      .addPrimitive(
        doc
          .createPrimitive()
          .setAttribute('POSITION', positionAccessor(doc, buffer, pos))
          .setIndices(indexAccessor(doc, buffer, idx, pos.length / 3)),
      );
  scene.addChild(doc.createNode(`${name}-a`).setMesh(mesh(`${name}-a`, a.positions, a.indices)));
  // World(B) = T(t)·R·S·T(u) with u = -(R·S)⁻¹ t, i.e. the linear part R·S and no translation.
  const u = inverseLinear(TRANSLATION).map((c) => -c);
  const offset = doc.createNode(`${name}-b-offset`).setTranslation(u).setMesh(mesh(`${name}-b`, local, b.indices));
  const transformed = doc
    .createNode(`${name}-b`)
    .setTranslation(TRANSLATION)
    .setRotation(ROTATION)
    .setScale(SCALE)
    .addChild(offset);
  scene.addChild(transformed);
  return doc;
}

/**
 * Reads the OBJ at `objPath` and writes the four fixtures into `outDir`
 * (created if needed). Returns [{ name, path, files, faces }].
 */
export async function makeGltfFixtures(objPath, outDir) {
  const name = path.basename(objPath).replace(/\.obj$/i, '');
  const { positions, triangles } = parseObj(fs.readFileSync(objPath, 'utf8'));
  if (triangles.length === 0) throw new Error(`${objPath}: no faces`);
  fs.mkdirSync(outDir, { recursive: true });
  const io = new NodeIO();
  const faces = triangles.length;
  const flat = triangles.flat();
  const written = [];
  const write = async (file, doc, companions = [], count = faces) => {
    const p = path.join(outDir, file);
    await io.write(p, doc);
    written.push({ name: file, path: p, files: [p, ...companions.map((c) => path.join(outDir, c))], faces: count });
  };

  await write(`${name}.glb`, singlePrimitive(name, positions, flat, Primitive.Mode.TRIANGLES));

  const bin = `${name}-two-nodes.bin`;
  await write(`${name}-two-nodes.gltf`, twoNodes(name, positions, triangles, bin), [bin]);

  // A strip cannot carry a face that repeats a vertex index: readers drop those
  // as joins. Such faces are left out of the strip file and of its count.
  const proper = triangles.filter(([a, b, c]) => a !== b && b !== c && a !== c);
  await write(
    `${name}-strip.glb`,
    singlePrimitive(name, positions, stripIndices(proper), Primitive.Mode.TRIANGLE_STRIP),
    [],
    proper.length,
  );

  const soup = new Float32Array(flat.length * 3);
  flat.forEach((v, i) => soup.set(positions.subarray(3 * v, 3 * v + 3), 3 * i));
  await write(`${name}-nonindexed.glb`, singlePrimitive(name, soup, null, Primitive.Mode.TRIANGLES));

  return written;
}

if (process.argv[1] && import.meta.url === pathToFileURL(path.resolve(process.argv[1])).href) {
  const [objPath, outDir] = process.argv.slice(2);
  if (!objPath || !outDir) {
    console.error('usage: node tests/node/make-gltf.mjs MESH.obj OUTDIR');
    process.exit(2);
  }
  const written = await makeGltfFixtures(objPath, outDir);
  for (const w of written) console.log(`${w.files.join(' + ')}: ${w.faces} faces`);
}
