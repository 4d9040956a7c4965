// Colouring point tiles by their LAS fields, shared by both viewers: the modes a tileset allows
// (from the vertex attributes its tiles carry), the ASPRS class colours, the colour ramp, and the
// panel's mode picker with a class legend whose boxes hide and show classes.

// ASPRS standard classes (LAS 1.4 R15 Table 17) and the colours lidar viewers commonly use.
export const CLASSES = [
  [0, 'Created, never classified', '#9e9e9e'], [1, 'Unclassified', '#cfcfcf'],
  [2, 'Ground', '#a0744f'], [3, 'Low Vegetation', '#b6e07a'], [4, 'Medium Vegetation', '#5fbf3f'],
  [5, 'High Vegetation', '#2f7f2f'], [6, 'Building', '#e0603a'], [7, 'Low Point (noise)', '#ff00ff'],
  [8, 'Reserved', '#808080'], [9, 'Water', '#3f7fff'], [10, 'Rail', '#8f5fbf'],
  [11, 'Road Surface', '#5a5a5a'], [12, 'Reserved (overlap)', '#ffbf00'],
  [13, 'Wire - Guard', '#ffff66'], [14, 'Wire - Conductor', '#ffee00'],
  [15, 'Transmission Tower', '#ffaa00'], [16, 'Wire-Structure Connector', '#ffd27f'],
  [17, 'Bridge Deck', '#9fa3b0'], [18, 'High Noise', '#ff66cc'], [19, 'Overhead Structure', '#c08040'],
  [20, 'Ignored Ground', '#6f5a40'], [21, 'Snow', '#f4f8ff'], [22, 'Temporal Exclusion', '#404040'],
];
const OTHER = '#ff4040';

export function classColor(value) {
  const entry = CLASSES.find(([v]) => v === value);
  return hexToRgb(entry ? entry[2] : OTHER);
}

export function hexToRgb(hex) {
  const n = parseInt(hex.slice(1), 16);
  return [(n >> 16) / 255, ((n >> 8) & 255) / 255, (n & 255) / 255];
}

// Blue → cyan → green → yellow → red for t in [0, 1].
export function ramp(t) {
  const stops = [[0.19, 0.21, 0.58], [0.0, 0.6, 0.85], [0.25, 0.75, 0.3], [0.95, 0.85, 0.2], [0.85, 0.2, 0.15]];
  const x = Math.min(Math.max(t, 0), 1) * (stops.length - 1);
  const i = Math.min(Math.floor(x), stops.length - 2);
  const f = x - i;
  return stops[i].map((a, k) => a + (stops[i + 1][k] - a) * f);
}

// The modes a tile allows, from its glTF primitive's attribute names.
export function colorModes(attributeNames) {
  const has = (name) => attributeNames.includes(name);
  const modes = [];
  if (has('COLOR_0')) modes.push('rgb');
  if (has('_CLASSIFICATION')) modes.push('classification');
  if (has('_INTENSITY')) modes.push('intensity');
  modes.push('elevation');
  if (has('_RETURN_NUMBER')) modes.push('return number');
  return modes;
}

// Intensity as grey, from a dark grey that still shows on the dark background to white.
export function intensityGrey(t) {
  return 0.15 + 0.85 * Math.min(Math.max(t, 0), 1);
}

// The panel's controls: a mode picker, and (in classification mode) a legend with a box per
// class the tiles hold. `onMode(mode)` and `onClassVisible(value, visible)` are called on change.
export function colorPanel(modes, classesPresent, onMode, onClassVisible) {
  const panel = document.getElementById('panel');
  const label = document.createElement('label');
  label.textContent = 'colour by ';
  const select = document.createElement('select');
  select.id = 'color-mode';
  for (const mode of modes) {
    const option = document.createElement('option');
    option.value = option.textContent = mode;
    select.appendChild(option);
  }
  label.appendChild(select);
  panel.appendChild(label);
  const legend = document.createElement('div');
  legend.id = 'legend';
  panel.appendChild(legend);
  const showLegend = (mode) => {
    legend.replaceChildren();
    if (mode !== 'classification') return;
    for (const value of [...classesPresent].sort((a, b) => a - b)) {
      const entry = CLASSES.find(([v]) => v === value);
      const row = document.createElement('label');
      const box = document.createElement('input');
      box.type = 'checkbox';
      box.checked = true;
      box.dataset.class = String(value);
      box.addEventListener('change', () => onClassVisible(value, box.checked));
      const swatch = document.createElement('span');
      swatch.className = 'swatch';
      swatch.style.background = entry ? entry[2] : OTHER;
      row.append(box, swatch, ` ${value} ${entry ? entry[1] : `Class ${value}`}`);
      legend.appendChild(row);
    }
  };
  select.addEventListener('change', () => { showLegend(select.value); onMode(select.value); });
  showLegend(select.value);
  return {
    setMode(mode) { select.value = mode; showLegend(mode); onMode(mode); },
    addClasses() { showLegend(select.value); },
  };
}
