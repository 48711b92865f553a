// Getting bytes into the page: local files (picker, drop) and sample URLs,
// with progress for big inputs.
import type { WireFile } from './protocol';

export const MESH_EXTENSIONS = ['.glb', '.gltf', '.obj'];
const PROGRESS_THRESHOLD = 4 * 1024 * 1024;

export type ReadProgress = (loaded: number, total: number) => void;

export const extensionOf = (name: string): string => {
  const dot = name.lastIndexOf('.');
  return dot < 0 ? '' : name.slice(dot).toLowerCase();
};

/** Orders dropped/picked files: the mesh file first, companions (.bin, images) after. */
export function orderFiles<T extends { name: string }>(files: T[]): T[] {
  const rank = (f: T): number => {
    const i = MESH_EXTENSIONS.indexOf(extensionOf(f.name));
    return i < 0 ? MESH_EXTENSIONS.length : i;
  };
  return [...files].sort((a, b) => rank(a) - rank(b));
}

function readWithProgress(file: File, onProgress: ReadProgress): Promise<ArrayBuffer> {
  return new Promise((resolve, reject) => {
    const reader = new FileReader();
    reader.onprogress = (e) => onProgress(e.loaded, e.lengthComputable ? e.total : file.size);
    reader.onload = () => resolve(reader.result as ArrayBuffer);
    reader.onerror = () => reject(new Error(`could not read the file (${reader.error?.message ?? 'unknown error'})`));
    reader.readAsArrayBuffer(file);
  });
}

/** Reads local files; progress is reported across all of them. */
export async function readFiles(files: File[], onProgress: ReadProgress): Promise<WireFile[]> {
  const total = files.reduce((s, f) => s + f.size, 0);
  let done = 0;
  const out: WireFile[] = [];
  for (const f of files) {
    const bytes = f.size >= PROGRESS_THRESHOLD
      ? await readWithProgress(f, (loaded) => onProgress(done + loaded, total))
      : await f.arrayBuffer();
    done += f.size;
    onProgress(done, total);
    out.push({ name: f.name, bytes });
  }
  return out;
}

/** Downloads one file, streaming when the server tells the size. */
export async function fetchFile(url: string, onProgress: ReadProgress): Promise<WireFile> {
  const name = decodeURIComponent(url.split('/').pop() ?? url);
  const res = await fetch(url);
  if (!res.ok) throw new Error(`download failed (HTTP ${res.status})`);
  const total = Number(res.headers.get('content-length') ?? 0);
  if (!res.body || total < PROGRESS_THRESHOLD) return { name, bytes: await res.arrayBuffer() };
  const bytes = new Uint8Array(total);
  const reader = res.body.getReader();
  let loaded = 0;
  for (;;) {
    const { done, value } = await reader.read();
    if (done) break;
    bytes.set(value, loaded);
    loaded += value.length;
    onProgress(loaded, total);
  }
  return { name, bytes: bytes.buffer.slice(0, loaded) };
}
