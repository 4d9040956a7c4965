// Numbers and controls for the stats panels.
export function formatCount(n) {
  return Math.round(n).toLocaleString('en-US');
}
export function formatBytes(n) {
  const units = ['B', 'KiB', 'MiB', 'GiB'];
  let i = 0;
  while (n >= 1024 && i < units.length - 1) { n /= 1024; i += 1; }
  return `${n.toFixed(i === 0 ? 0 : 1)} ${units[i]}`;
}

// What both panels start their stats line with.
export function drawnSummary(tiles, loaded, points, triangles) {
  return `${tiles} tiles drawn, ${loaded} loaded · ` +
    (points > 0 ? `${formatCount(points)} points` : `${formatCount(triangles)} triangles`);
}

// The panel's screen-space-error slider: `set(pixels)` on every move, the value shown beside it.
export function onScreenSpaceError(set) {
  const slider = document.getElementById('sse');
  slider.addEventListener('input', () => {
    set(Number(slider.value));
    document.getElementById('sse-value').textContent = slider.value;
  });
}
