// Saving what the page computed as files: a blob as a download, and the file
// name stem the downloads of a mesh share.

/** Saves `blob` as a download named `name`. */
export function download(blob: Blob, name: string): void {
  const url = URL.createObjectURL(blob);
  const a = document.createElement('a');
  a.href = url;
  a.download = name;
  document.body.append(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(url), 10_000);
}

/** Saves `bytes` as a download named `name` of MIME type `type`. */
export function downloadBytes(bytes: Uint8Array, type: string, name: string): void {
  download(new Blob([bytes as Uint8Array<ArrayBuffer>], { type }), name);
}

/** The file name stem of the downloads of mesh `label` (the name shown for it): without "(+N more)" and extension. */
export const fileStem = (label: string | undefined): string =>
  (label ?? 'mesh').replace(/ \(\+\d+ more\)$/, '').replace(/\.[^.]+$/, '');
