// The parts of a tileset of parts (a CAD assembly), for both viewers: parts.json (named by
// tileset.json's asset.extras.parts: id, name, assembly path, CAD layer, bounds per part), and
// the panel that finds a part by name, shows the one picked, hides it or its CAD layers, or shows
// everything again. The viewer does the drawing: it gets the ids to highlight, hide or fly to.

// parts.json of the tileset at `base` ('/tiles/'), or null when the tileset names no parts.
export async function loadParts(base) {
  const tileset = await (await fetch(`${base}tileset.json`)).json();
  const uri = tileset.asset && tileset.asset.extras && tileset.asset.extras.parts;
  if (!uri) return null;
  const response = await fetch(`${base}${uri}`);
  if (!response.ok) throw new Error(`${base}${uri}: HTTP ${response.status}`);
  return response.json();
}

// Ids of the parts whose name holds `text` (case-insensitive; all for empty text).
export function findParts(parts, text) {
  const needle = text.trim().toLowerCase();
  return parts.parts.filter((p) => p.name.toLowerCase().includes(needle)).map((p) => p.id);
}

// The CAD layers of a part ("a; b" names two), as a list.
export function layerNames(part) {
  return part && part.layer ? part.layer.split('; ') : [];
}

// Each CAD layer's name and the ids of the parts on it, in first-seen order.
export function partsByLayer(parts) {
  const layers = new Map();
  for (const p of parts.parts)
    for (const name of layerNames(p)) {
      if (!layers.has(name)) layers.set(name, []);
      layers.get(name).push(p.id);
    }
  return layers;
}

// The box around the parts `ids` in the tileset's frame, or null when none has triangles.
export function boundsOf(parts, ids) {
  let box = null;
  for (const id of ids) {
    const b = parts.parts[id] && parts.parts[id].bounds;
    if (!b) continue;
    box = box ? [Math.min(box[0], b[0]), Math.min(box[1], b[1]), Math.min(box[2], b[2]),
                 Math.max(box[3], b[3]), Math.max(box[4], b[4]), Math.max(box[5], b[5])]
              : [...b];
  }
  return box;
}

// The panel's part section. `view` draws: view.highlight(ids), view.hide(ids), view.flyTo(ids).
// Returns what the viewer calls when a part is picked on screen (its id, or null for none).
export function partsPanel(parts, view) {
  const panel = document.getElementById('panel');
  const section = document.createElement('div');
  section.id = 'parts';
  const title = document.createElement('div');
  title.textContent = `${parts.parts.length} parts · click one to pick it`;
  const find = document.createElement('input');
  find.id = 'part-find';
  find.type = 'search';
  find.placeholder = 'find a part by name';
  const found = document.createElement('div');
  found.id = 'part-found';
  const picked = document.createElement('div');
  picked.id = 'part-picked';
  const hide = document.createElement('button');
  hide.id = 'part-hide';
  hide.textContent = 'hide';
  hide.disabled = true;
  const showAll = document.createElement('button');
  showAll.id = 'part-show-all';
  showAll.textContent = 'show all';
  section.append(title, find, found, picked, hide, showAll);
  // One checkbox per CAD layer: a part on a layer turned off is hidden.
  const layers = partsByLayer(parts);
  const layersOff = new Set();
  const layerBoxes = new Map();
  if (layers.size > 0) {
    // Folded at first: an assembly may have dozens of layers.
    const list = document.createElement('details');
    list.id = 'part-layers';
    const summary = document.createElement('summary');
    summary.textContent = `${layers.size} CAD layers`;
    list.appendChild(summary);
    for (const [name, ids] of layers) {
      const label = document.createElement('label');
      const box = document.createElement('input');
      box.type = 'checkbox';
      box.checked = true;
      box.addEventListener('change', () => setLayer(name, box.checked));
      layerBoxes.set(name, box);
      label.append(box, `${name} (${ids.length})`);
      list.append(label);
    }
    section.appendChild(list);
  }
  panel.appendChild(section);

  const hidden = new Set();
  let current = null;
  const redraw = () => {
    const ids = new Set(hidden);
    for (const name of layersOff) for (const id of layers.get(name) || []) ids.add(id);
    view.hide([...ids]);
  };
  // Ticks or clears the layer's box; redraws unless the caller will once for several.
  const showLayer = (name, shown) => {
    const box = layerBoxes.get(name);
    if (!box) return false;
    box.checked = shown;
    if (shown) layersOff.delete(name); else layersOff.add(name);
    return true;
  };
  const setLayer = (name, shown) => {
    const known = showLayer(name, shown);
    if (known) redraw();
    return known;
  };
  const select = (id) => {
    current = id;
    const part = id === null ? null : parts.parts[id];
    picked.replaceChildren();
    if (part) {
      const name = document.createElement('b');
      name.textContent = part.name || '(unnamed)';
      const path = document.createElement('div');
      path.className = 'part-path';
      path.textContent = part.path || '';
      picked.append(name, path);
      if (part.layer) {
        const layer = document.createElement('div');
        layer.className = 'part-layer';
        layer.textContent = `layer: ${part.layer}`;
        picked.append(layer);
      }
    }
    hide.disabled = part === null;
    view.highlight(part ? [id] : []);
  };
  const search = (text) => {
    const ids = text.trim() ? findParts(parts, text) : [];
    found.textContent = text.trim() ? `${ids.length} found` : '';
    view.highlight(ids);
    if (ids.length > 0) view.flyTo(ids);
    return ids;
  };
  find.addEventListener('keydown', (e) => { if (e.key === 'Enter') search(find.value); });
  hide.addEventListener('click', () => {
    if (current === null) return;
    hidden.add(current);
    redraw();
    select(null);
  });
  const showEverything = () => {
    hidden.clear();
    for (const name of [...layersOff]) showLayer(name, true);
    redraw();  // once, not per layer
  };
  showAll.addEventListener('click', showEverything);
  return {
    picked: select,
    find: (text) => { find.value = text; return search(text); },
    hide: (ids) => { for (const id of ids) hidden.add(id); redraw(); },
    showAll: showEverything,
    shown: () => picked.textContent,
    layers: () => [...layers.keys()],
    setLayer,
  };
}
