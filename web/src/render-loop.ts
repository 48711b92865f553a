// Rendering on demand, shared by the 3D view and the UV view: the renderer, a
// render loop drawing at most once per animation frame (held while shaders
// compile), pointer events coalesced to the latest one per frame, clicks told
// apart from drags, and a wait for the next drawn frame.
import * as THREE from 'three';

/** A WebGL renderer (antialiased, drawing buffer kept for screenshots, pixel ratio ≤ 2) whose canvas, with `data-testid` = `testid`, is appended to `container`. */
export function createRenderer(container: HTMLElement, testid: string): THREE.WebGLRenderer {
  const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
  renderer.setPixelRatio(Math.min(window.devicePixelRatio, 2));
  renderer.domElement.dataset['testid'] = testid;
  container.appendChild(renderer.domElement);
  return renderer;
}

/** Longest wait for shaders to compile before rendering anyway (a lost context never reports them ready). */
const COMPILE_WAIT_MS = 3000;

/**
 * Runs `draw` at the next animation frame on request, once however often it is
 * requested before then; while held, requests wait and draw once on release.
 */
class RenderScheduler {
  private requested = false;
  private holds = 0;
  private waiting = false;

  constructor(private readonly draw: () => void) {}

  /** Draws at the next animation frame (or, while held, after the release). */
  request(): void {
    if (this.holds > 0) {
      this.waiting = true;
      return;
    }
    if (this.requested) return;
    this.requested = true;
    requestAnimationFrame(() => {
      this.requested = false;
      if (this.holds > 0) this.waiting = true;
      else this.draw();
    });
  }

  /** Holds drawing until `work` settles (at most COMPILE_WAIT_MS), then requests a draw if one waited. */
  async holdWhile(work: Promise<unknown>): Promise<void> {
    this.holds++;
    let timer = 0;
    try {
      await Promise.race([work.catch(() => undefined), new Promise((r) => (timer = window.setTimeout(r, COMPILE_WAIT_MS)))]);
    } finally {
      clearTimeout(timer);
      this.holds--;
      if (this.holds === 0 && this.waiting) {
        this.waiting = false;
        this.request();
      }
    }
  }
}

/** Head start given to shader compilation where its end cannot be observed without blocking. */
const COMPILE_HEAD_START_MS = 10;

/**
 * Compiles the shaders `scene` needs through `renderer` while `scheduler` holds
 * drawing, so that the next frame does not stall on them; resolves when they are
 * ready (with KHR_parallel_shader_compile) or after a short head start (without
 * it, e.g. SwiftShader or Firefox, where `compileAsync` would also warn).
 */
function precompile(renderer: THREE.WebGLRenderer, scene: THREE.Scene, camera: THREE.Camera, scheduler: RenderScheduler): Promise<void> {
  if (renderer.extensions.has('KHR_parallel_shader_compile')) return scheduler.holdWhile(renderer.compileAsync(scene, camera));
  renderer.compile(scene, camera);
  return scheduler.holdWhile(new Promise((resolve) => setTimeout(resolve, COMPILE_HEAD_START_MS)));
}

/** Draws `scene` through `camera` with `renderer` on request: at most once per animation frame, and not while its shaders compile. */
export class RenderLoop {
  private readonly scheduler = new RenderScheduler(() => this.renderNow());

  constructor(
    private readonly renderer: THREE.WebGLRenderer,
    private readonly scene: THREE.Scene,
    private readonly camera: THREE.Camera,
  ) {}

  /** Renders at the next animation frame (once, however often it is called before then). */
  readonly request = (): void => this.scheduler.request();

  /** Compiles the shaders of the scene as it is now, holding renders until they are ready (see `precompile`). */
  prepare(): Promise<void> {
    return precompile(this.renderer, this.scene, this.camera, this.scheduler);
  }

  /** Renders now. */
  renderNow(): void {
    this.renderer.render(this.scene, this.camera);
  }
}

/** Takes `handle` and returns a listener that passes `handle` only the latest event of each animation frame. */
export function latestPerFrame<E>(handle: (e: E) => void): (e: E) => void {
  let pending: E | null = null;
  return (e) => {
    if (pending === null) {
      requestAnimationFrame(() => {
        const ev = pending!;
        pending = null;
        handle(ev);
      });
    }
    pending = e;
  };
}

/** A click moves the pointer less than this (CSS px) and lasts less than CLICK_MS; otherwise it is a drag (orbit, pan). */
const CLICK_PX = 5;
const CLICK_MS = 600;

/** Calls `handle` with the release of each left-button click on `el` (see CLICK_PX, CLICK_MS); drags call nothing. */
export function onClick(el: HTMLElement, handle: (e: PointerEvent) => void): void {
  let down: { x: number; y: number; t: number } | null = null;
  el.addEventListener('pointerdown', (e) => {
    down = e.button === 0 ? { x: e.clientX, y: e.clientY, t: performance.now() } : null;
  });
  el.addEventListener('pointerup', (e) => {
    if (!down || e.button !== 0) return;
    const click = Math.hypot(e.clientX - down.x, e.clientY - down.y) < CLICK_PX && performance.now() - down.t < CLICK_MS;
    down = null;
    if (click) handle(e);
  });
}

/** Longest wait for an animation frame (hidden pages get none). */
const FRAME_WAIT_MS = 1000;

/** Resolves in a task after the next animation frame (so after that frame was drawn), or after FRAME_WAIT_MS without one. */
export function afterNextFrame(): Promise<void> {
  return new Promise((resolve) => {
    const timer = setTimeout(resolve, FRAME_WAIT_MS);
    requestAnimationFrame(() => {
      clearTimeout(timer);
      setTimeout(resolve, 0);
    });
  });
}
