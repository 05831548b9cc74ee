#!/usr/bin/env node
// Link WESL with wesl-js (npm `wesl`) against lodkit's WESL package, as a WebGPU app would.
//
//   node .ci/browser/wesl-link.mjs PACKAGE_DIR JOBS.json
//
// PACKAGE_DIR holds wesl.toml and the package's *.wesl files (shader_lib/wesl/lodkit). JOBS.json is an array of
// { "root": "<WESL source of main.wesl>", "conditions": { "NAME": true }, "out": "<path>" };
// each linked result (plain WGSL) is written to its "out".
// Exit: 0 all linked, 1 some job failed to link (its error on stderr), 2 usage error.
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { link } from 'wesl';

function die(message) {
  console.error(`wesl-link: ${message}`);
  process.exit(2);
}

const [pkgDir, jobsFile] = process.argv.slice(2);
if (!pkgDir || !jobsFile || process.argv.length > 4) die('usage: node wesl-link.mjs PACKAGE_DIR JOBS.json');
const toml = path.join(pkgDir, 'wesl.toml');
if (!fs.existsSync(toml)) die(`no wesl.toml in ${pkgDir}`);
const edition = /edition\s*=\s*"([^"]+)"/.exec(fs.readFileSync(toml, 'utf8'))?.[1];
const root = path.join(pkgDir, /root\s*=\s*"\.?\/?([^"]*)"/.exec(fs.readFileSync(toml, 'utf8'))?.[1] ?? '.');
const modules = Object.fromEntries(
  fs.readdirSync(root).filter((f) => f.endsWith('.wesl')).sort()
    .map((f) => [f, fs.readFileSync(path.join(root, f), 'utf8')]),
);
if (Object.keys(modules).length === 0) die(`no .wesl files in ${root}`);
const lodkit = { name: 'lodkit', edition, modules };
const here = path.dirname(fileURLToPath(import.meta.url));
const version = JSON.parse(fs.readFileSync(path.join(here, 'node_modules/wesl/package.json'), 'utf8')).version;

const jobs = JSON.parse(fs.readFileSync(jobsFile, 'utf8'));
let failed = 0;
for (const job of jobs) {
  try {
    const linked = await link({
      weslSrc: { 'main.wesl': job.root },
      rootModuleName: 'main',
      libs: [lodkit],
      conditions: job.conditions ?? {},
    });
    fs.writeFileSync(job.out, linked.dest);
  } catch (e) {
    failed += 1;
    console.error(`${job.out}: ${e.message ?? e}`);
  }
}
console.log(`wesl ${version}: linked ${jobs.length - failed} of ${jobs.length} (${Object.keys(modules).length} lodkit modules, edition ${edition})`);
process.exit(failed ? 1 : 0);
