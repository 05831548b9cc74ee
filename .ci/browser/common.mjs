// Shared helpers for the headless-Chromium CI checks (tint.mjs, page.mjs).
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { chromium } from 'playwright-core';

// Debian's chromium by default; override with LODKIT_CHROMIUM=/path/to/chrome.
export const CHROMIUM = process.env.LODKIT_CHROMIUM || '/usr/bin/chromium';

// Flags: no sandbox (CI containers), no network chatter, and WebGPU enabled.
// On Linux, `--enable-unsafe-webgpu` alone is what exposes WebGPU; without a
// GPU Dawn then falls back to the bundled SwiftShader Vulkan ICD
// (adapter.info: vendor "google", architecture "swiftshader").
export const ARGS = [
  '--no-sandbox',
  '--disable-quic',
  '--no-first-run',
  '--disable-background-networking',
  '--disable-component-update',
  '--disable-sync',
  '--enable-unsafe-webgpu',
];

// Timeout (ms) for any single wait: navigation, load state, one evaluate.
export const TIMEOUT_MS = Number(process.env.LODKIT_BROWSER_TIMEOUT_MS) || 30_000;

// Print a message and exit with code 2 (usage / environment problem).
export function die(msg) {
  console.error(`error: ${msg}`);
  process.exit(2);
}

// Launch headless Chromium (playwright gives it a fresh temporary profile).
export async function launch() {
  if (!fs.existsSync(CHROMIUM)) {
    die(`Chromium not found at ${CHROMIUM}: apt-get install chromium ` +
        `(or set LODKIT_CHROMIUM to a Chromium/Chrome binary)`);
  }
  try {
    return await chromium.launch({
      executablePath: CHROMIUM, headless: true, args: ARGS, timeout: TIMEOUT_MS,
    });
  } catch (e) {
    die(`could not launch ${CHROMIUM}: ${e.message.split('\n')[0]}`);
  }
}

// Reject if `promise` takes longer than `ms` (page.evaluate has no timeout).
export function withTimeout(promise, what, ms = TIMEOUT_MS) {
  let timer;
  const t = new Promise((_, reject) => {
    timer = setTimeout(() => reject(new Error(`timed out after ${ms} ms: ${what}`)), ms);
  });
  return Promise.race([promise, t]).finally(() => clearTimeout(timer));
}

// An empty page under a temp dir: file:// is a secure context, so
// navigator.gpu exists there (about:blank / data: URLs are not reliable).
export function blankPageUrl() {
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'lodkit-browser-'));
  const file = path.join(dir, 'index.html');
  fs.writeFileSync(file, '<!doctype html><meta charset="utf-8"><title>lodkit</title>\n');
  return { url: `file://${file}`, cleanup: () => fs.rmSync(dir, { recursive: true, force: true }) };
}
