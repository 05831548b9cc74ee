#!/usr/bin/env node
// Open an HTML file in headless Chromium, check that it renders cleanly and
// take a full-page screenshot.
//
//   node .ci/browser/page.mjs HTML_FILE SCREENSHOT_PNG
//
// Problems: an <img> not loaded (complete && naturalWidth > 0), a console
// error, an uncaught page error, a failed request.
// Exit: 0 no problems, 1 problems found, 2 usage error / no browser.
import fs from 'node:fs';
import path from 'node:path';
import { pathToFileURL } from 'node:url';
import { launch, withTimeout, die, TIMEOUT_MS } from './common.mjs';

const [html, shot] = process.argv.slice(2);
if (!html || !shot || process.argv.length > 4) die('usage: node page.mjs HTML_FILE SCREENSHOT_PNG');
if (!fs.existsSync(html) || !fs.statSync(html).isFile()) die(`no such file: ${html}`);
if (!fs.existsSync(path.dirname(path.resolve(shot)))) die(`screenshot directory missing: ${shot}`);

async function main(browser) {
  const page = await browser.newPage();
  page.setDefaultTimeout(TIMEOUT_MS);
  const problems = [];
  // Collect problems from the moment the page starts loading.
  page.on('console', (m) => {
    if (m.type() === 'error') {
      const loc = m.location();
      const at = loc.url ? ` (${loc.url}${loc.lineNumber > 0 ? `:${loc.lineNumber + 1}` : ''})` : '';
      problems.push(`console error: ${m.text()}${at}`);
    }
  });
  page.on('pageerror', (e) => problems.push(`page error: ${e.message}`));
  page.on('requestfailed', (r) => problems.push(`request failed: ${r.url()} (${r.failure()?.errorText})`));

  await page.goto(pathToFileURL(path.resolve(html)).href, { waitUntil: 'load' });
  // networkidle: no requests for 500 ms. Not fatal if a page keeps polling.
  await page.waitForLoadState('networkidle').catch((e) => problems.push(`network never idle: ${e.message.split('\n')[0]}`));

  const imgs = await withTimeout(page.evaluate(() => [...document.images].map((img) => ({
    src: img.getAttribute('src'), url: img.currentSrc || img.src,
    complete: img.complete, w: img.naturalWidth, h: img.naturalHeight,
  }))), 'reading <img> state');
  const good = imgs.filter((i) => i.complete && i.w > 0);
  for (const i of imgs) {
    if (!(i.complete && i.w > 0)) {
      problems.push(`image not loaded: ${i.src} (complete=${i.complete}, naturalWidth=${i.w})`);
    }
  }

  await page.screenshot({ path: shot, fullPage: true });
  console.log(`images: ${good.length}/${imgs.length} loaded`);
  console.log(`screenshot: ${shot}`);
  for (const p of problems) console.log(`PROBLEM ${p}`);
  console.log(problems.length ? `FAIL ${html}: ${problems.length} problem(s)` : `ok   ${html}`);
  return problems.length ? 1 : 0;
}

const browser = await launch();
let code = 2;
try {
  code = await main(browser);
} catch (e) {
  // e.g. a navigation/screenshot timeout: the page is broken, not the usage.
  console.log(`FAIL ${html}: ${e.message.split('\n')[0]}`);
  code = 1;
} finally {
  await browser.close().catch(() => {});
}
process.exit(code);
