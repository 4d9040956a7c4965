// CesiumJS viewer for the tileset lodforge serve hands out at /tiles/: no Ion token, no online
// imagery or terrain (no globe), flies to the tileset, shows what is loaded and drawn, and
// lets the screen-space error be chosen. window.lodforge reports to tests.
import { drawnSummary, formatBytes, onScreenSpaceError } from '../format.js';
import { boundsOf, loadParts, partsPanel } from '../parts_panel.js';
import { CLASSES, classColor, colorModes, colorPanel, hexToRgb } from '../point_colors.js';
import { MeshoptDecoder } from 'meshoptimizer/decoder';

const Cesium = window.Cesium;
const report = (window.lodforge = { loaded: false, failed: [], error: null, tilesLoaded: 0, frames: 0 });

// The root tile's glTF: its primitive's attribute names, and the classes it holds (the root's
// points are spread over the whole cloud, so its classes are the common ones).
async function rootContent(tileset) {
  const json = await (await fetch('/tiles/tileset.json')).json();
  // Implicit tiling is for meshes only: no point fields to colour.
  if (json.root.implicitTiling) return null;
  let tile = json.root;
  while (!tile.content && tile.children) tile = tile.children[0];
  if (!tile.content) return null;
  const bytes = await (await fetch(`/tiles/${tile.content.uri}`)).arrayBuffer();
  const view = new DataView(bytes);
  const jsonLength = view.getUint32(12, true);
  const gltf = JSON.parse(new TextDecoder().decode(new Uint8Array(bytes, 20, jsonLength)));
  const attributes = gltf.meshes[0].primitives[0].attributes;
  const bin = 20 + jsonLength + 8;
  // A scalar attribute's values (4 bytes apart), decoded first where meshopt-compressed (point
  // tiles are, by default).
  const values = async (name, read) => {
    if (!(name in attributes)) return [];
    const accessor = gltf.accessors[attributes[name]];
    const bufferView = gltf.bufferViews[accessor.bufferView];
    const packed = bufferView.extensions && bufferView.extensions.EXT_meshopt_compression;
    let data = view;
    let at = bin + (bufferView.byteOffset ?? 0);
    if (packed) {
      await MeshoptDecoder.ready;
      const decoded = new Uint8Array(packed.count * packed.byteStride);
      MeshoptDecoder.decodeGltfBuffer(decoded, packed.count, packed.byteStride,
        new Uint8Array(bytes, bin + (packed.byteOffset ?? 0), packed.byteLength), packed.mode, packed.filter);
      data = new DataView(decoded.buffer);
      at = 0;
    }
    return Array.from({ length: accessor.count }, (_, i) => read(data, at + 4 * i));
  };
  const classes = new Set(await values('_CLASSIFICATION', (data, at) => data.getUint8(at)));
  const wide = (await values('_INTENSITY', (data, at) => data.getUint16(at, true))).some((v) => v > 255);
  return { names: Object.keys(attributes), classes, intensityMax: wide ? 65535 : 255,
           hasMetadata: !!(gltf.extensions && gltf.extensions.EXT_structural_metadata &&
                           gltf.extensions.EXT_structural_metadata.propertyAttributes) };
}

const vec3 = (rgb) => `vec3(${rgb.map((x) => x.toFixed(3)).join(', ')})`;

// A custom shader over the metadata the tiles carry: u_mode picks the colouring, u_hidden has a
// bit per hidden class (0–30), elevation is the distance from the Earth's centre across the
// tileset's range.
function pointShader(modes, names) {
  const has = (name) => names.includes(name);
  const classLookup = CLASSES.map(([v, , hex]) => `if (c == ${v}) return ${vec3(hexToRgb(hex))};`).join('\n    ');
  const index = (mode) => modes.indexOf(mode);
  return new Cesium.CustomShader({
    uniforms: {
      u_mode: { type: Cesium.UniformType.INT, value: 0 },
      u_hidden: { type: Cesium.UniformType.INT, value: 0 },
      u_intensityMax: { type: Cesium.UniformType.FLOAT, value: 255 },
      u_heights: { type: Cesium.UniformType.VEC2, value: new Cesium.Cartesian2(0, 1) },
    },
    fragmentShaderText: `
  vec3 classColor(int c) {
    ${classLookup}
    return ${vec3(classColor(-1))};
  }
  vec3 ramp(float t) {
    t = clamp(t, 0.0, 1.0) * 4.0;
    vec3 a = vec3(0.19, 0.21, 0.58), b = vec3(0.0, 0.6, 0.85), c = vec3(0.25, 0.75, 0.3),
         d = vec3(0.95, 0.85, 0.2), e = vec3(0.85, 0.2, 0.15);
    if (t < 1.0) return mix(a, b, t);
    if (t < 2.0) return mix(b, c, t - 1.0);
    if (t < 3.0) return mix(c, d, t - 2.0);
    return mix(d, e, t - 3.0);
  }
  void fragmentMain(FragmentInput fsInput, inout czm_modelMaterial material) {
    int c = ${has('_CLASSIFICATION') ? 'int(fsInput.metadata.classification)' : '-1'};
    if (c >= 0 && c < 31 && ((u_hidden >> c) & 1) == 1) discard;
    if (u_mode == ${index('classification')}) material.diffuse = classColor(c);
    ${has('_INTENSITY') ? `if (u_mode == ${index('intensity')}) material.diffuse = vec3(0.15 + 0.85 * clamp(float(fsInput.metadata.intensity) / u_intensityMax, 0.0, 1.0));` : ''}
    if (u_mode == ${index('elevation')})
      material.diffuse = ramp((length(fsInput.attributes.positionWC) - u_heights.x) / (u_heights.y - u_heights.x));
    ${has('_RETURN_NUMBER') ? `if (u_mode == ${index('return number')}) {
      int r = clamp(int(fsInput.metadata.return_number), 1, 5);
      material.diffuse = r == 1 ? vec3(0.9, 0.2, 0.15) : r == 2 ? vec3(0.95, 0.6, 0.1) : r == 3 ? vec3(0.95, 0.9, 0.2) : r == 4 ? vec3(0.3, 0.8, 0.3) : vec3(0.2, 0.5, 0.95);
    }` : ''}
  }`,
  });
}

// Point tilesets with LAS fields get the mode picker and the legend.
async function addColouring(scene, tileset) {
  const root = await rootContent(tileset);
  if (!root || !root.hasMetadata) return;
  const modes = colorModes(root.names);
  const shader = pointShader(modes, root.names);
  tileset.customShader = shader;
  const sphere = tileset.boundingSphere;
  const centre = Cesium.Cartesian3.magnitude(sphere.center);
  shader.setUniform('u_heights', new Cesium.Cartesian2(centre - sphere.radius, centre + sphere.radius));
  shader.setUniform('u_intensityMax', root.intensityMax);
  let hidden = 0;
  const panel = colorPanel(modes, root.classes, (mode) => {
    shader.setUniform('u_mode', modes.indexOf(mode));
    scene.requestRender();
  }, (value, visible) => {
    if (value < 31) hidden = visible ? hidden & ~(1 << value) : hidden | (1 << value);
    shader.setUniform('u_hidden', hidden);
    scene.requestRender();
  });
  report.colorModes = modes;
  report.setColorMode = (mode) => panel.setMode(mode);
  report.setClassVisible = (value, visible) => {
    const box = document.querySelector(`#legend input[data-class="${value}"]`);
    if (box) box.checked = visible;
    if (value < 31) hidden = visible ? hidden & ~(1 << value) : hidden | (1 << value);
    shader.setUniform('u_hidden', hidden);
    scene.requestRender();
  };
  report.classes = () => [...root.classes];
}

// Tilesets of parts (EXT_mesh_features + the tiles' property tables): click a part to pick it,
// find parts by name, hide them. A style keys on each feature's "id" property.
async function addParts(viewer, tileset) {
  const parts = await loadParts('/tiles/');
  if (!parts) return;
  // Set lookups rather than style expressions: an expression with a term per part would be
  // 100,000 terms deep for a big assembly.
  let highlighted = new Set(), hidden = new Set();
  const highlight = Cesium.Color.fromCssColorString('#ffd21f');
  const style = new Cesium.Cesium3DTileStyle();
  style.show = { evaluate: (feature) => !hidden.has(feature.getProperty('id')) };
  style.color = {
    evaluateColor: (feature, result) => Cesium.Color.clone(
      highlighted.has(feature.getProperty('id')) ? highlight : Cesium.Color.WHITE, result),
  };
  tileset.style = style;
  const restyle = () => {
    tileset.makeStyleDirty();
    viewer.scene.requestRender();
  };
  const panel = partsPanel(parts, {
    highlight: (ids) => { highlighted = new Set(ids); restyle(); },
    hide: (ids) => { hidden = new Set(ids); restyle(); },
    flyTo: (ids) => {
      const b = boundsOf(parts, ids);
      if (!b) return;
      const toWorld = (x, y, z) =>
        Cesium.Matrix4.multiplyByPoint(tileset.root.computedTransform, new Cesium.Cartesian3(x, y, z),
                                       new Cesium.Cartesian3());
      const sphere = Cesium.BoundingSphere.fromPoints([toWorld(b[0], b[1], b[2]), toWorld(b[3], b[4], b[5])]);
      viewer.camera.flyToBoundingSphere(sphere, { duration: 0 });
    },
  });
  const featureAt = (x, y) => {
    const picked = viewer.scene.pick(new Cesium.Cartesian2(x, y));
    return picked instanceof Cesium.Cesium3DTileFeature ? picked : null;
  };
  const handler = new Cesium.ScreenSpaceEventHandler(viewer.scene.canvas);
  handler.setInputAction((click) => {
    const feature = featureAt(click.position.x, click.position.y);
    panel.picked(feature ? feature.getProperty('id') : null);
  }, Cesium.ScreenSpaceEventType.LEFT_CLICK);
  // For tests: what is at a pixel (CSS pixels of the canvas), as the tile's property table says.
  report.parts = {
    count: parts.parts.length,
    pick: (x, y) => {
      const f = featureAt(x, y);
      if (!f) return null;
      const color = f.color;
      return { id: f.getProperty('id'), name: f.getProperty('name'), path: f.getProperty('path'),
               layer: f.getProperty('layer') || '', highlighted: color.red === 1 && color.blue < 0.2 };
    },
    find: (text) => panel.find(text),
    isolate: (id) => panel.hide(parts.parts.map((p) => p.id).filter((i) => i !== id)),
    hide: (id) => panel.hide([id]),
    showAll: () => panel.showAll(),
    shown: () => panel.shown(),
    layers: () => panel.layers(),
    setLayer: (name, shown) => panel.setLayer(name, shown),
    idle: () => tileset.tilesLoaded,
  };
}

async function main() {
  const viewer = new Cesium.Viewer('view', {
    baseLayer: false, baseLayerPicker: false, geocoder: false, timeline: false, animation: false,
    homeButton: false, sceneModePicker: false, navigationHelpButton: false, fullscreenButton: false,
    infoBox: false, selectionIndicator: false,
    // No imagery and no terrain: a globe would be a blank ball; the model alone is shown (and
    // no globe's shaders and tiles are made at all).
    globe: false, skyBox: false, skyAtmosphere: false,
    // Draw only when something changed (the camera, a tile, a setting): an idle view costs no CPU.
    requestRenderMode: true, maximumRenderTimeChange: Infinity,
  });
  viewer.scene.backgroundColor = Cesium.Color.fromCssColorString('#12151a');
  const tileset = await Cesium.Cesium3DTileset.fromUrl('/tiles/tileset.json', {
    maximumScreenSpaceError: 16,
    // Point tilesets: points grow with their tile's geometric error, so a coarse tile is not a
    // sprinkle of single pixels (meshes are not affected).
    pointCloudShading: { attenuation: true, maximumAttenuation: 6 },
  });
  viewer.scene.primitives.add(tileset);
  // Loaded once the final framing's tiles are in (an implicit tileset is framed twice).
  let framed = false, setUp = false;
  frameTileset(viewer, tileset, () => {
    framed = true;
    if (setUp) report.loaded = true;
  });
  report.rootCorners = () => rootCorners(viewer, tileset);
  tileset.tileFailed.addEventListener((e) => report.failed.push(`${e.url}: ${e.message}`));
  // Tiles with a model (an implicit tileset's subtree files are loaded as tiles too).
  tileset.tileLoad.addEventListener((tile) => { if (!tile.hasImplicitContent) report.tilesLoaded += 1; });
  // Loaded: every tile the view needs, once the panels are set up too (the tiles may be in first).
  tileset.allTilesLoaded.addEventListener(() => { if (setUp && framed) report.loaded = true; });
  // What is drawn this frame: tiles, and their triangles or points.
  let drawn = { tiles: 0, triangles: 0, points: 0 };
  tileset.tileVisible.addEventListener((tile) => {
    drawn.tiles += 1;
    const content = tile.content;
    drawn.triangles += content.trianglesLength ?? 0;
    drawn.points += content.pointsLength ?? 0;
  });
  const stats = document.getElementById('stats');
  viewer.scene.postRender.addEventListener(() => {
    stats.textContent =
      drawnSummary(drawn.tiles, report.tilesLoaded, drawn.points, drawn.triangles) +
      ` · ${formatBytes(tileset.totalMemoryUsageInBytes)} in tiles`;
    report.drawn = drawn;
    report.frames += 1;
    drawn = { tiles: 0, triangles: 0, points: 0 };
  });
  onScreenSpaceError((pixels) => {
    tileset.maximumScreenSpaceError = pixels;
    viewer.scene.requestRender();
  });
  await addColouring(viewer.scene, tileset);
  await addParts(viewer, tileset);
  setUp = true;
  if (tileset.tilesLoaded && framed) report.loaded = true;
}

// The camera looks down at 45 degrees from where the root's bounding sphere just fills the
// narrower field of view, so the whole tileset is on screen when it opens (viewer.flyTo
// zoomed into big tilesets: an airborne cloud opened on a few trees at ground level).
// `done` is called once the framing is final and its tiles are loaded.
function frameTileset(viewer, tileset, done) {
  frameSphere(viewer, tileset.boundingSphere);
  // An implicit tileset's root volume is its whole octree cube: once the first subtree is in,
  // its root tile's own volume (the tight box of the subtree's metadata) frames the view.
  if (!tileset.root.implicitTileset) {
    done();
    return;
  }
  const remove = viewer.scene.postRender.addEventListener(() => {
    const first = tileset.root.children[0];
    if (!first) return;
    remove();
    frameSphere(viewer, first.boundingSphere);
    let frames = 0;
    const settle = viewer.scene.postRender.addEventListener(() => {
      if (++frames < 2) {
        viewer.scene.requestRender();  // a frame of the new view first
        return;
      }
      if (!tileset.tilesLoaded) return;
      settle();
      done();
    });
    viewer.scene.requestRender();
  });
}

function frameSphere(viewer, sphere) {
  // Cesium's `fov` is the wider of the two angles; `fovy` the vertical.
  const frustum = viewer.camera.frustum;
  const half = Math.min(frustum.fov, frustum.fovy) / 2;
  const range = (1.05 * sphere.radius) / Math.sin(half);
  viewer.camera.flyToBoundingSphere(sphere, {
    duration: 0,
    offset: new Cesium.HeadingPitchRange(0, -Math.PI / 4, range),
  });
}

// For tests: the root's bounding box corners in CSS pixels of the canvas (null: behind the
// camera).
function rootCorners(viewer, tileset) {
  const root = tileset.root.implicitTileset ? tileset.root.children[0] : tileset.root;
  if (!root) return [];
  const volume = root.boundingVolume.boundingVolume;
  const corners = [];
  if (volume instanceof Cesium.OrientedBoundingBox) {
    const axes = [0, 1, 2].map((c) => Cesium.Matrix3.getColumn(volume.halfAxes, c, new Cesium.Cartesian3()));
    for (let i = 0; i < 8; ++i) {
      const corner = Cesium.Cartesian3.clone(volume.center);
      for (let a = 0; a < 3; ++a) {
        const step = Cesium.Cartesian3.multiplyByScalar(axes[a], (i >> a) & 1 ? 1 : -1, new Cesium.Cartesian3());
        Cesium.Cartesian3.add(corner, step, corner);
      }
      corners.push(corner);
    }
  } else {
    corners.push(tileset.boundingSphere.center);
  }
  return corners.map((c) => {
    const p = Cesium.SceneTransforms.worldToWindowCoordinates(viewer.scene, c);
    return p ? [p.x, p.y] : null;
  });
}

main().catch((e) => { report.error = String((e && e.stack) || e); });
