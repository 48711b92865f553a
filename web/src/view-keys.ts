// Keyboard access to the 3D view: the canvas takes focus (Tab) with a name
// saying how to use it; focused, the arrow keys orbit and F frames the mesh.
import type { Viewer } from './viewer';

/** Radians per arrow-key press (Shift: a quarter of it). */
const STEP = Math.PI / 24;

/** Makes `viewer`'s canvas focusable and named, and turns arrow keys into orbiting while it has focus. */
export function wireViewKeys(viewer: Viewer): void {
  const canvas = viewer.canvas;
  canvas.tabIndex = 0;
  canvas.setAttribute('role', 'application');
  canvas.setAttribute('aria-roledescription', '3D view');
  canvas.setAttribute('aria-label', 'The mesh in 3D: drag or arrow keys to orbit, right-drag to pan, scroll to zoom, F to frame the mesh');
  canvas.addEventListener('keydown', (e) => {
    const step = e.shiftKey ? STEP / 4 : STEP;
    const turn: Record<string, [number, number]> = {
      ArrowLeft: [step, 0], ArrowRight: [-step, 0], ArrowUp: [0, step], ArrowDown: [0, -step],
    };
    const t = turn[e.key];
    if (t) viewer.orbit(t[0], t[1]);
    else if (e.key === 'f' || e.key === 'F') viewer.frame();
    else return;
    e.preventDefault();
  });
}
