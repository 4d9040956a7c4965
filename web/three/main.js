// three.js viewer with NASA-AMMOS 3d-tiles-renderer for the tileset at /tiles/: the tileset is
// moved to the origin (a georeferenced one sits 6,000 km away in ECEF) and turned so its local
// up is +y, an orbit camera frames it; stats and a screen-space-error slider as on the Cesium
// page. window.lodforge reports to tests.
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import { MeshoptDecoder } from 'three/examples/jsm/libs/meshopt_decoder.module.js';
import { TilesRenderer } from '3d-tiles-renderer';
import { GLTFExtensionsPlugin } from '3d-tiles-renderer/plugins';
import { drawnSummary, formatBytes, formatCount, onScreenSpaceError } from '../format.js';
import { classColor, colorModes, colorPanel, intensityGrey, ramp } from '../point_colors.js';

const report = (window.lodforge = { loaded: false, failed: [], error: null, tilesLoaded: 0 });

// Point tiles coloured by a LAS field: each loaded Points object keeps its own colours and is
// recoloured on the CPU (RGBA; a hidden class gets alpha 0, which alphaTest discards).
const RETURN_COLORS = [[0.9, 0.2, 0.15], [0.95, 0.6, 0.1], [0.95, 0.9, 0.2], [0.3, 0.8, 0.3], [0.2, 0.5, 0.95]];
const colouring = { mode: null, hidden: new Set(), classes: new Set(), heights: null, intensityMax: 1,
                    panel: null, points: new Set() };

function recolour(points) {
  const g = points.geometry;
  const color = g.getAttribute('color');
  const rgb = points.userData.rgb;
  const cls = g.getAttribute('_classification');
  const intensity = g.getAttribute('_intensity');
  const returns = g.getAttribute('_return_number');
  const position = g.getAttribute('position');
  const p = new THREE.Vector3();
  for (let i = 0; i < color.count; ++i) {
    let c = [1, 1, 1];
    const mode = colouring.mode;
    if (mode === 'rgb' && rgb) c = [rgb[4 * i] / 255, rgb[4 * i + 1] / 255, rgb[4 * i + 2] / 255];
    else if (mode === 'classification' && cls) c = classColor(cls.getX(i));
    else if (mode === 'intensity' && intensity) c = new Array(3).fill(intensityGrey(intensity.getX(i) / colouring.intensityMax));
    else if (mode === 'return number' && returns) c = RETURN_COLORS[Math.min(Math.max(returns.getX(i), 1), 5) - 1];
    else if (mode === 'elevation' && colouring.heights) {
      p.fromBufferAttribute(position, i).applyMatrix4(points.matrixWorld);
      c = ramp((p.y - colouring.heights[0]) / (colouring.heights[1] - colouring.heights[0]));
    }
    const hidden = cls && colouring.hidden.has(cls.getX(i));
    const out = color.array;  // Uint8, normalised: written as bytes
    out[4 * i] = Math.round(c[0] * 255);
    out[4 * i + 1] = Math.round(c[1] * 255);
    out[4 * i + 2] = Math.round(c[2] * 255);
    out[4 * i + 3] = hidden ? 0 : 255;
  }
  color.needsUpdate = true;
}

function recolourAll() {
  for (const points of colouring.points) recolour(points);
}

// A tile's Points, as they load: RGBA colours to write into, the original RGB kept, the
// classes and intensities it holds noted; the panel made for the first.
function preparePoints(points) {
  const g = points.geometry;
  const names = Object.keys(g.attributes).map((n) => (n === 'color' ? 'COLOR_0' : n.toUpperCase()));
  const old = g.getAttribute('color');
  let rgb = null;
  if (old) {  // COLOR_0 (normalised: getX and friends give 0..1)
    rgb = new Uint8Array(old.count * 4);
    for (let i = 0; i < old.count; ++i) {
      rgb[4 * i] = Math.round(old.getX(i) * 255);
      rgb[4 * i + 1] = Math.round(old.getY(i) * 255);
      rgb[4 * i + 2] = Math.round(old.getZ(i) * 255);
    }
  }
  points.userData.rgb = rgb;
  g.setAttribute('color', new THREE.BufferAttribute(new Uint8Array(g.getAttribute('position').count * 4), 4, true));
  points.material.vertexColors = true;
  points.material.alphaTest = 0.5;
  points.material.needsUpdate = true;
  const cls = g.getAttribute('_classification');
  let added = false;
  if (cls) for (let i = 0; i < cls.count; ++i) {
    if (!colouring.classes.has(cls.getX(i))) { colouring.classes.add(cls.getX(i)); added = true; }
  }
  const intensity = g.getAttribute('_intensity');
  if (intensity) for (let i = 0; i < intensity.count; ++i)
    colouring.intensityMax = Math.max(colouring.intensityMax, intensity.getX(i) > 255 ? 65535 : 255);
  if (!colouring.panel) {
    const modes = colorModes(names);
    colouring.mode = modes[0];
    report.colorModes = modes;
    colouring.panel = colorPanel(modes, colouring.classes, (mode) => {
      colouring.mode = mode;
      recolourAll();
    }, (value, visible) => {
      if (visible) colouring.hidden.delete(value); else colouring.hidden.add(value);
      recolourAll();
    });
  } else if (added) {
    colouring.panel.addClasses();
  }
  colouring.points.add(points);
  points.updateMatrixWorld(true);
  recolour(points);
}

report.setColorMode = (mode) => colouring.panel && colouring.panel.setMode(mode);
report.setClassVisible = (value, visible) => {
  const box = document.querySelector(`#legend input[data-class="${value}"]`);
  if (visible) colouring.hidden.delete(value); else colouring.hidden.add(value);
  if (box) box.checked = visible;
  recolourAll();
};
report.classes = () => [...colouring.classes];

function main() {
  const renderer = new THREE.WebGLRenderer({ antialias: true });
  renderer.setPixelRatio(window.devicePixelRatio);
  renderer.setSize(window.innerWidth, window.innerHeight);
  renderer.setClearColor(0x12151a);
  document.getElementById('view').appendChild(renderer.domElement);
  const scene = new THREE.Scene();
  scene.add(new THREE.HemisphereLight(0xffffff, 0x445566, 2.0));
  const sun = new THREE.DirectionalLight(0xffffff, 1.5);
  sun.position.set(1, 2, 3);
  scene.add(sun);
  const camera = new THREE.PerspectiveCamera(60, window.innerWidth / window.innerHeight, 0.01, 1e7);
  const controls = new OrbitControls(camera, renderer.domElement);

  const tiles = new TilesRenderer('/tiles/tileset.json');
  // EXT_meshopt_compression contents (lodforge tiles --compress meshopt).
  tiles.registerPlugin(new GLTFExtensionsPlugin({ meshoptDecoder: MeshoptDecoder }));
  tiles.errorTarget = 16;
  tiles.setCamera(camera);
  tiles.setResolutionFromRenderer(camera, renderer);
  // Georeferenced tilesets: undo the root transform's rotation and ECEF translation.
  const pivot = new THREE.Group();
  pivot.add(tiles.group);
  scene.add(pivot);
  // Framed once the root is in: its bounding sphere, in the tileset's local frame (the root
  // transform undone, z-up turned to y-up).
  let framed = false;
  const frame = () => {
    const rootTransform = tiles.rootTileSet && tiles.rootTileSet.root && tiles.rootTileSet.root.transform;
    if (rootTransform) {
      tiles.group.matrixAutoUpdate = false;
      tiles.group.matrix.copy(new THREE.Matrix4().fromArray(rootTransform).invert());
    }
    pivot.rotation.x = -Math.PI / 2;  // 3D Tiles are z-up, three.js is y-up
    pivot.updateMatrixWorld(true);
    const sphere = new THREE.Sphere();
    if (!tiles.getBoundingSphere(sphere)) return false;
    sphere.applyMatrix4(tiles.group.matrixWorld);
    controls.target.copy(sphere.center);
    camera.position.copy(sphere.center)
      .add(new THREE.Vector3(0.6, 0.8, 1.2).normalize().multiplyScalar(sphere.radius * 2.2));
    camera.near = sphere.radius / 1000;
    camera.far = sphere.radius * 100;
    camera.updateProjectionMatrix();
    controls.update();
    colouring.heights = [sphere.center.y - sphere.radius, sphere.center.y + sphere.radius];
    return true;
  };
  tiles.addEventListener('load-model', (e) => {
    report.tilesLoaded += 1;
    e.scene.traverse((o) => { if (o.isPoints) preparePoints(o); });
  });
  tiles.addEventListener('dispose-model', (e) => {
    e.scene.traverse((o) => colouring.points.delete(o));
  });
  tiles.addEventListener('load-error', (e) => {
    report.failed.push(`${e.url}: ${e.error && e.error.message}`);
  });
  tiles.addEventListener('tiles-load-end', () => { if (framed && report.tilesLoaded > 0) report.loaded = true; });

  onScreenSpaceError((pixels) => { tiles.errorTarget = pixels; });
  window.addEventListener('resize', () => {
    camera.aspect = window.innerWidth / window.innerHeight;
    camera.updateProjectionMatrix();
    renderer.setSize(window.innerWidth, window.innerHeight);
    tiles.setResolutionFromRenderer(camera, renderer);
  });
  const stats = document.getElementById('stats');
  renderer.setAnimationLoop(() => {
    if (!framed) framed = frame();
    controls.update();
    camera.updateMatrixWorld();
    tiles.update();
    renderer.render(scene, camera);
    const info = renderer.info;
    const points = info.render.points;
    stats.textContent =
      drawnSummary(tiles.visibleTiles.size, report.tilesLoaded, points, info.render.triangles) +
      ` · ${formatCount(info.memory.geometries)} geometries, ${formatBytes(tiles.lruCache.cachedBytes ?? 0)} cached`;
  });
}

try {
  main();
} catch (e) {
  report.error = String((e && e.stack) || e);
}
