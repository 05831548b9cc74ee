#!/usr/bin/env node
// Link probe shaders against lodkit's WESL package with wesl-js INSIDE Chromium (as a WebGPU page
// does), run them on the page's WebGPU adapter, and print the output words as JSON.
//
//   node .ci/browser/webgpu-probe.mjs PACKAGE_DIR JOBS.json
//
// PACKAGE_DIR is shader_lib/wesl/lodkit, or `-` when every job carries "code", WGSL linked
// elsewhere (npm-user.mjs: the installed npm package). JOBS.json: [{ "name", "root" (WESL of package::main:
// a compute shader `main`, @workgroup_size(1), one workgroup per case, reading
// `array<u32>` at @group(0) @binding(0) and writing `array<u32>` at binding 1), "conditions",
// "input": [u32...], "cases", "outputs" (words per case) }].
// Prints { "adapter": "...", "results": { name: [u32...] } } on stdout.
// Exit: 0 ran every job, 1 a job failed to link or run (message on stderr), 2 usage/environment.
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { launch, withTimeout, die, TIMEOUT_MS } from './common.mjs';

const [pkgDir, jobsFile] = process.argv.slice(2);
if (!pkgDir || !jobsFile || process.argv.length > 4) die('usage: node webgpu-probe.mjs PACKAGE_DIR JOBS.json');
const linkedElsewhere = pkgDir === '-';
if (!linkedElsewhere && !fs.existsSync(path.join(pkgDir, 'wesl.toml'))) die(`no wesl.toml in ${pkgDir}`);
const here = path.dirname(fileURLToPath(import.meta.url));
const weslDist = path.join(here, 'node_modules/wesl/dist');
if (!fs.existsSync(weslDist)) die('npm package `wesl` is missing: npm ci --prefix .ci/browser');
const jobs = JSON.parse(fs.readFileSync(jobsFile, 'utf8'));
if (linkedElsewhere && !jobs.every((j) => typeof j.code === 'string')) die('with PACKAGE_DIR `-` every job needs "code"');
const moduleFiles = linkedElsewhere ? [] : fs.readdirSync(pkgDir).filter((f) => f.endsWith('.wesl')).sort();
const edition = linkedElsewhere ? null : /edition\s*=\s*"([^"]+)"/.exec(fs.readFileSync(path.join(pkgDir, 'wesl.toml'), 'utf8'))?.[1];

// The page's origin is served from disk by request interception: nothing listens on the port.
const ORIGIN = 'http://localhost:9'; // localhost is a secure context (WebGPU needs one)
const PAGE = `<!doctype html><meta charset="utf-8"><title>lodkit WebGPU probe</title>
<script type="module">
  import { link } from '/wesl/index.js';
  window.lodkitLink = link;
  window.lodkitReady = true;
</script>`;
const TYPES = { '.js': 'text/javascript', '.html': 'text/html', '.wesl': 'text/plain' };

// In the page: fetch the package, link with wesl-js, run each job, return output words.
async function runJobs({ files, edition, jobs }) {
  const link = window.lodkitLink;
  const modules = {};
  for (const f of files) modules[f] = await (await fetch(`/lodkit/${f}`)).text();
  const lodkit = { name: 'lodkit', edition, modules };
  if (!navigator.gpu) return { error: 'navigator.gpu is missing' };
  const adapter = await navigator.gpu.requestAdapter();
  if (!adapter) return { error: 'no WebGPU adapter' };
  const device = await adapter.requestDevice();
  const info = adapter.info;
  const results = {};
  for (const job of jobs) {
    let code = job.code;
    if (code === undefined) {
      try {
        code = (await link({ weslSrc: { 'main.wesl': job.root }, rootModuleName: 'main', libs: [lodkit], conditions: job.conditions })).dest;
      } catch (e) {
        return { error: `${job.name}: wesl-js cannot link: ${e.message}` };
      }
    }
    device.pushErrorScope('validation');
    const module = device.createShaderModule({ code });
    const pipeline = device.createComputePipeline({ layout: 'auto', compute: { module, entryPoint: 'main' } });
    const input = device.createBuffer({ size: Math.max(16, job.input.length * 4), usage: GPUBufferUsage.STORAGE, mappedAtCreation: true });
    new Uint32Array(input.getMappedRange()).set(job.input);
    input.unmap();
    const size = Math.max(16, job.cases * job.outputs * 4);
    const output = device.createBuffer({ size, usage: GPUBufferUsage.STORAGE | GPUBufferUsage.COPY_SRC });
    const read = device.createBuffer({ size, usage: GPUBufferUsage.MAP_READ | GPUBufferUsage.COPY_DST });
    const group = device.createBindGroup({ layout: pipeline.getBindGroupLayout(0), entries: [
      { binding: 0, resource: { buffer: input } }, { binding: 1, resource: { buffer: output } }] });
    const encoder = device.createCommandEncoder();
    const pass = encoder.beginComputePass();
    pass.setPipeline(pipeline);
    pass.setBindGroup(0, group);
    pass.dispatchWorkgroups(job.cases);
    pass.end();
    encoder.copyBufferToBuffer(output, 0, read, 0, size);
    device.queue.submit([encoder.finish()]);
    const err = await device.popErrorScope();
    if (err) return { error: `${job.name}: ${err.message}\n${code}` };
    await read.mapAsync(GPUMapMode.READ);
    results[job.name] = Array.from(new Uint32Array(read.getMappedRange()).slice(0, job.cases * job.outputs));
    read.unmap();
  }
  return { adapter: `${info.vendor} ${info.architecture} ${info.description}`.trim(), results };
}

const browser = await launch();
let code = 2;
try {
  const page = await browser.newPage();
  page.setDefaultTimeout(TIMEOUT_MS);
  const errors = [];
  page.on('pageerror', (e) => errors.push(e.message));
  await page.route(`${ORIGIN}/**`, (route) => {
    const url = new URL(route.request().url());
    let file = null;
    if (url.pathname === '/') return route.fulfill({ body: PAGE, contentType: TYPES['.html'] });
    if (url.pathname.startsWith('/wesl/')) file = path.join(weslDist, path.basename(url.pathname));
    if (url.pathname.startsWith('/lodkit/')) file = path.join(pkgDir, path.basename(url.pathname));
    if (!file || !fs.existsSync(file)) return route.fulfill({ status: 404, body: 'not found' });
    return route.fulfill({ body: fs.readFileSync(file), contentType: TYPES[path.extname(file)] ?? 'application/octet-stream' });
  });
  await page.goto(`${ORIGIN}/`);
  await page.waitForFunction(() => window.lodkitReady === true, null, { timeout: TIMEOUT_MS }).catch(() => {
    die(`wesl-js did not load in the page: ${errors.join('; ') || 'timeout'}`);
  });
  const r = await withTimeout(page.evaluate(runJobs, { files: moduleFiles, edition, jobs }), 'probe jobs');
  if (r.error) {
    console.error(`error: ${r.error}`);
    code = /adapter|navigator\.gpu/.test(r.error) ? 2 : 1;
  } else {
    console.log(JSON.stringify(r));
    code = 0;
  }
} catch (e) {
  console.error(`error: ${e.message}`);
} finally {
  await browser.close().catch(() => {});
}
process.exit(code);
