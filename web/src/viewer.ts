// The three.js view: one mesh with flat shading, an optional edge overlay,
// orbit controls, camera framed to the mesh. Renders on demand, not in a loop.
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';

export interface MeshData {
  positions: Float32Array;
  indices: Uint32Array;
  edges: Uint32Array | null;
}

export class Viewer {
  private readonly renderer: THREE.WebGLRenderer;
  private readonly scene = new THREE.Scene();
  private readonly camera = new THREE.PerspectiveCamera(40, 1, 0.01, 100);
  private readonly controls: OrbitControls;
  private readonly group = new THREE.Group();
  private mesh: THREE.Mesh | null = null;
  private wire: THREE.LineSegments | null = null;
  private wireVisible = true;
  private frameRequested = false;

  constructor(private readonly container: HTMLElement) {
    this.renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
    this.renderer.setPixelRatio(Math.min(window.devicePixelRatio, 2));
    this.renderer.domElement.dataset['testid'] = 'canvas';
    container.appendChild(this.renderer.domElement);

    this.scene.background = new THREE.Color(0x2b313b);
    this.scene.add(new THREE.HemisphereLight(0xf2f5ff, 0x3a3f48, 1.6));
    const key = new THREE.DirectionalLight(0xffffff, 1.8);
    key.position.set(0.6, 1, 1.2);
    this.camera.add(key); // the key light follows the view
    this.scene.add(this.camera, this.group);

    this.controls = new OrbitControls(this.camera, this.renderer.domElement);
    this.controls.addEventListener('change', () => this.requestRender());

    new ResizeObserver(() => this.resize()).observe(container);
    this.resize();
  }

  get hasMesh(): boolean {
    return this.mesh !== null;
  }

  /** Replaces the shown mesh and frames the camera to it. */
  show(data: MeshData): void {
    this.clear();
    const geometry = new THREE.BufferGeometry();
    const position = new THREE.BufferAttribute(data.positions, 3);
    geometry.setAttribute('position', position);
    geometry.setIndex(new THREE.BufferAttribute(data.indices, 1));
    geometry.computeBoundingSphere();
    const material = new THREE.MeshStandardMaterial({
      color: 0xc9d2de,
      roughness: 0.75,
      metalness: 0.05,
      flatShading: true,
      side: THREE.DoubleSide,
      polygonOffset: true, // push faces back so the edge overlay is not z-fighting
      polygonOffsetFactor: 1,
      polygonOffsetUnits: 1,
    });
    this.mesh = new THREE.Mesh(geometry, material);
    this.group.add(this.mesh);

    if (data.edges) {
      const lines = new THREE.BufferGeometry();
      lines.setAttribute('position', position); // shares the vertex buffer
      lines.setIndex(new THREE.BufferAttribute(data.edges, 1));
      lines.boundingSphere = geometry.boundingSphere;
      const lineMaterial = new THREE.LineBasicMaterial({ color: 0x1a2130, transparent: true, opacity: 0.28 });
      this.wire = new THREE.LineSegments(lines, lineMaterial);
      this.wire.visible = this.wireVisible;
      this.group.add(this.wire);
    }
    this.frame();
  }

  get wireframeAvailable(): boolean {
    return this.wire !== null;
  }

  setWireframe(visible: boolean): void {
    this.wireVisible = visible;
    if (this.wire) this.wire.visible = visible;
    this.requestRender();
  }

  /** Points the camera at the mesh's bounding sphere. */
  frame(): void {
    const sphere = this.mesh?.geometry.boundingSphere;
    if (!sphere) return;
    const r = sphere.radius > 0 ? sphere.radius : 1;
    const fov = THREE.MathUtils.degToRad(this.camera.fov);
    const fit = Math.min(fov, 2 * Math.atan(Math.tan(fov / 2) * this.camera.aspect));
    const distance = (r / Math.sin(fit / 2)) * 1.08;
    const dir = new THREE.Vector3(0.55, 0.4, 1).normalize();
    this.camera.position.copy(sphere.center).addScaledVector(dir, distance);
    this.camera.near = distance / 100;
    this.camera.far = distance * 10;
    this.camera.updateProjectionMatrix();
    this.controls.target.copy(sphere.center);
    this.controls.minDistance = r * 0.05;
    this.controls.maxDistance = distance * 5;
    this.controls.update();
    this.requestRender();
  }

  private clear(): void {
    for (const obj of [this.mesh, this.wire]) {
      if (!obj) continue;
      this.group.remove(obj);
      (obj.material as THREE.Material).dispose();
    }
    this.mesh?.geometry.dispose();
    this.wire?.geometry.dispose();
    this.mesh = null;
    this.wire = null;
  }

  private resize(): void {
    const { clientWidth: w, clientHeight: h } = this.container;
    if (w === 0 || h === 0) return;
    this.renderer.setSize(w, h, false);
    this.renderer.domElement.style.width = '100%';
    this.renderer.domElement.style.height = '100%';
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
    this.requestRender();
  }

  requestRender(): void {
    if (this.frameRequested) return;
    this.frameRequested = true;
    requestAnimationFrame(() => {
      this.frameRequested = false;
      this.renderer.render(this.scene, this.camera);
    });
  }

  /** Renders now (used before screenshots and after loading, so "ready" means drawn). */
  renderNow(): void {
    this.renderer.render(this.scene, this.camera);
  }
}
