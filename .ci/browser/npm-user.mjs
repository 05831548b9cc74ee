#!/usr/bin/env node
// A user's script in a fresh node project that installed lodkit's npm package and npm `wesl`:
// it imports the bundle from the package as an application does and links each job's shader.
// integration_tests/webgpu_page.rs copies it into the project (imports resolve from there) and
// runs the linked shaders in Chromium with webgpu-probe.mjs.
//
//   node link.mjs JOBS.json OUT.json
//
// JOBS.json: webgpu-probe.mjs's jobs ({ "name", "root", "conditions", ... }). OUT.json: the same
// jobs, each with "code", the linked WGSL. Exit: 0 all linked, 1 a job failed, 2 usage.
import fs from 'node:fs';
import { link } from 'wesl';
import lodkit from 'lodkit';

const [jobsFile, outFile] = process.argv.slice(2);
if (!jobsFile || !outFile || process.argv.length > 4) {
  console.error('usage: node link.mjs JOBS.json OUT.json');
  process.exit(2);
}
if (lodkit?.name !== 'lodkit' || Object.keys(lodkit.modules ?? {}).length === 0) {
  console.error(`the package's default export is not lodkit's bundle: ${JSON.stringify(lodkit)?.slice(0, 200)}`);
  process.exit(1);
}
const jobs = JSON.parse(fs.readFileSync(jobsFile, 'utf8'));
for (const job of jobs) {
  try {
    const linked = await link({
      weslSrc: { 'main.wesl': job.root },
      rootModuleName: 'main',
      libs: [lodkit],
      conditions: job.conditions ?? {},
    });
    job.code = linked.dest;
  } catch (e) {
    console.error(`${job.name}: wesl-js cannot link: ${e.message ?? e}`);
    process.exit(1);
  }
}
fs.writeFileSync(outFile, JSON.stringify(jobs));
console.log(`linked ${jobs.length} shaders with lodkit ${Object.keys(lodkit.modules).length} modules, edition ${lodkit.edition}`);
