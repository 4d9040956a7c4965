// Two pages (cesium/, three/) built into dist/. CesiumJS is used as its prebuilt bundle (workers,
// assets and widgets are files it loads at run time): copied to dist/assets/cesium, not bundled.
import { cpSync } from 'node:fs';
import { resolve } from 'node:path';
import { defineConfig } from 'vite';

const here = import.meta.dirname ?? new URL('.', import.meta.url).pathname;

export default defineConfig({
  root: here,
  base: '/',
  logLevel: 'warn',
  build: {
    outDir: resolve(here, 'dist'),
    emptyOutDir: true,
    chunkSizeWarningLimit: 2000,
    rollupOptions: {
      input: {
        cesium: resolve(here, 'cesium/index.html'),
        three: resolve(here, 'three/index.html'),
      },
    },
  },
  plugins: [
    {
      name: 'copy-cesium-build',
      closeBundle() {
        cpSync(resolve(here, 'node_modules/cesium/Build/Cesium'), resolve(here, 'dist/assets/cesium'),
               { recursive: true });
      },
    },
  ],
});
