#!/usr/bin/env node
// Compile every *.wgsl file in DIR with the browser's WebGPU implementation
// (Chromium's Dawn/Tint, SwiftShader adapter when there is no GPU).
//
//   node .ci/browser/tint.mjs DIR
//
// Exit: 0 all files compiled without errors, 1 some file failed,
//       2 usage error / no .wgsl files / no browser / no WebGPU adapter.
import fs from 'node:fs';
import path from 'node:path';
import { launch, blankPageUrl, withTimeout, die, TIMEOUT_MS } from './common.mjs';

const dir = process.argv[2];
if (!dir || process.argv.length > 3) die('usage: node tint.mjs DIR');
if (!fs.existsSync(dir) || !fs.statSync(dir).isDirectory()) die(`not a directory: ${dir}`);
const files = fs.readdirSync(dir).filter((f) => f.endsWith('.wgsl')).sort();
if (files.length === 0) die(`no .wgsl files in ${dir}`);

// In the page: get an adapter and a device with every standard feature the
// adapter offers (so `enable subgroups;` etc. work); keep the device on window.
async function initGpu() {
  if (!navigator.gpu) return { error: `navigator.gpu is missing (secure context: ${isSecureContext})` };
  const adapter = await navigator.gpu.requestAdapter();
  if (!adapter) return { error: 'navigator.gpu.requestAdapter() returned null' };
  const features = [...adapter.features].filter((f) => !f.startsWith('chromium-'));
  const device = await adapter.requestDevice({ requiredFeatures: features });
  window.lost = null;
  device.lost.then((i) => { window.lost = `device lost (${i.reason}): ${i.message}`; });
  window.device = device;
  const { vendor, architecture, device: dev, description, isFallbackAdapter } = adapter.info;
  return {
    vendor, architecture, device: dev, description, isFallbackAdapter,
    // No adapter.featureLevel attribute: core adapters expose this feature.
    featureLevel: adapter.features.has('core-features-and-limits') ? 'core' : 'compatibility',
    features,
  };
}

// In the page: compile one module; return its messages plus any validation error.
async function compile(code) {
  if (window.lost) return { messages: [], validation: window.lost };
  const device = window.device;
  device.pushErrorScope('validation');
  const module = device.createShaderModule({ code });
  const info = await module.getCompilationInfo();
  const err = await device.popErrorScope();
  return {
    messages: info.messages.map(({ type, lineNum, linePos, message }) => ({ type, lineNum, linePos, message })),
    validation: err ? err.message : null,
  };
}

const indent = (s) => s.replace(/\n/g, '\n      ');

async function main(browser) {
  const page = await browser.newPage();
  page.setDefaultTimeout(TIMEOUT_MS);
  const blank = blankPageUrl();
  try {
    await page.goto(blank.url);
    const gpu = await withTimeout(page.evaluate(initGpu), 'WebGPU adapter/device');
    if (gpu.error) {
      console.error(`error: no WebGPU adapter: ${gpu.error} ` +
        '(needs --enable-unsafe-webgpu and the SwiftShader Vulkan ICD, libvk_swiftshader.so)');
      return 2;
    }
    console.log(`adapter: vendor=${gpu.vendor || '?'} architecture=${gpu.architecture || '?'} ` +
      `device=${gpu.device || '-'} description=${gpu.description || '-'} ` +
      `fallback=${gpu.isFallbackAdapter} featureLevel=${gpu.featureLevel}`);
    console.log(`browser: Chromium ${browser.version()}; device features: ${gpu.features.join(' ') || '-'}`);

    let failed = 0;
    for (const name of files) {
      const code = fs.readFileSync(path.join(dir, name), 'utf8');
      const srcLines = code.split('\n');
      let r;
      try {
        r = await withTimeout(page.evaluate(compile, code), `compiling ${name}`);
      } catch (e) {
        r = { messages: [], validation: e.message.split('\n')[0] };
      }
      const errors = r.messages.filter((m) => m.type === 'error');
      const ok = errors.length === 0 && !r.validation;
      if (!ok) failed++;
      console.log(`${ok ? 'ok  ' : 'FAIL'} ${name}`);
      for (const m of r.messages) {
        // type is 'error', 'warning' or 'info'; only errors fail the file.
        console.log(`  ${m.type}: ${name}:${m.lineNum}:${m.linePos}: ${indent(m.message)}`);
        const src = srcLines[m.lineNum - 1];
        if (m.type === 'error' && src !== undefined) {
          console.log(`      ${src}\n      ${' '.repeat(Math.max(0, m.linePos - 1))}^`);
        }
      }
      // The validation error repeats the compile errors; show it only if it adds something.
      if (r.validation && errors.length === 0) console.log(`  error: ${indent(r.validation)}`);
    }
    console.log(`${files.length - failed}/${files.length} shader(s) compiled` +
      (failed ? `, ${failed} failed` : ''));
    return failed ? 1 : 0;
  } finally {
    blank.cleanup();
  }
}

const browser = await launch();
let code = 2;
try {
  code = await main(browser);
} catch (e) {
  console.error(`error: ${e.message}`);
} finally {
  await browser.close().catch(() => {});
}
process.exit(code);
