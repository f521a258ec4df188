// The report page of `simsr demo` in headless Chromium (Debian's chromium driven by playwright-core):
// it loads from disk without console errors, its Table 1 equals report.json's numbers, and a
// screenshot of the viewer shows the surface (non-background pixels in both halves, the
// prediction's half coloured).
//
//     node tests/cli/test_report_page.js DEMO_OUT_DIR NODE_MODULES_DIR [CHROMIUM]
//
// Exit 0: passed; 1: a check failed; 77: playwright-core or chromium missing.
const fs = require('fs');
const path = require('path');
const [outDir, modules, chromiumPath = '/usr/bin/chromium'] = process.argv.slice(2);
let chromium;
try {
  ({ chromium } = require(path.resolve(modules, 'playwright-core')));
} catch (e) {
  console.log('MISSING: playwright-core in ' + modules + ': ' + e.message);
  process.exit(77);
}
if (!fs.existsSync(chromiumPath)) {
  console.log('MISSING: ' + chromiumPath + ' (Debian package chromium)');
  process.exit(77);
}
let failed = 0;
const check = (ok, what) => { if (!ok) { failed++; console.log('FAIL: ' + what); } };
(async () => {
  const report = JSON.parse(fs.readFileSync(path.join(outDir, 'report.json'), 'utf8'));
  const page_file = path.join(outDir, 'report', 'index.html');
  const browser = await chromium.launch({ executablePath: chromiumPath, args: ['--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--no-sandbox'] });
  const page = await browser.newPage({ viewport: { width: 1100, height: 1600 } });
  const errors = [];
  page.on('console', (m) => { if (m.type() === 'error') errors.push(m.text()); });
  page.on('pageerror', (e) => errors.push(String(e)));
  page.on('requestfailed', (r) => errors.push('request failed: ' + r.url()));
  await page.goto('file://' + page_file);
  await page.waitForFunction(() => document.title === 'simsr report: ready', null, { timeout: 60000 });
  check(errors.length === 0, 'console errors: ' + JSON.stringify(errors));
  check(await page.evaluate(() => typeof THREE !== 'undefined'), 'three.js is loaded (vendored next to the page)');
  const rows = await page.$$eval('#table1 tbody tr', (trs) => trs.map((tr) => ({
    method: tr.dataset.method,
    cells: Object.fromEntries([...tr.querySelectorAll('td[data-stat]')].map((td) => [td.dataset.stat, td.textContent])),
  })));
  const names = Object.keys(report.table1);
  check(JSON.stringify(rows.map((r) => r.method)) === JSON.stringify(names), 'table rows ' + rows.map((r) => r.method) + ' are ' + names);
  for (const r of rows) {
    for (const s of ['mean', 'median', 'std', 'max', 'min']) {
      const want = report.table1[r.method].relative[s], got = parseFloat(r.cells['relative_' + s]);
      check(Math.abs(got - want) <= 1e-4 * Math.abs(want) + 1e-300, `${r.method} relative ${s}: page ${got}, report ${want}`);
    }
    const want = report.table1[r.method].normalized.mean, got = parseFloat(r.cells.normalized_mean);
    check(Math.abs(got - want) <= 1e-4, `${r.method} normalized mean: page ${got}, report ${want}`);
  }
  // The viewer: pause, then a screenshot of the canvas.
  await page.click('#play');
  const shot = await page.locator('#viewer').screenshot();
  fs.writeFileSync(path.join(outDir, 'report', 'viewer_test.png'), shot);
  const px = await page.evaluate(async (b64) => {
    const img = new Image();
    img.src = 'data:image/png;base64,' + b64;
    await img.decode();
    const c = document.createElement('canvas');
    c.width = img.width; c.height = img.height;
    const g = c.getContext('2d');
    g.drawImage(img, 0, 0);
    const d = g.getImageData(0, 0, c.width, c.height).data;
    let left = 0, right = 0, coloured = 0;
    for (let y = 0; y < c.height; ++y) for (let x = 0; x < c.width; ++x) {
      const i = 4 * (y * c.width + x), r = d[i], gg = d[i + 1], b = d[i + 2];
      if (255 * 3 - r - gg - b > 60) { if (x < c.width / 2) left++; else right++; }
      if (x < c.width / 2 && Math.abs(b - r) > 80) coloured++;
    }
    return { left, right, coloured, total: c.width * c.height / 2 };
  }, shot.toString('base64'));
  check(px.left > 0.02 * px.total, `prediction half shows the surface: ${px.left} of ${px.total} pixels`);
  check(px.right > 0.02 * px.total, `truth half shows the surface: ${px.right} of ${px.total} pixels`);
  check(px.coloured > 0.01 * px.total, `prediction half is coloured by its error: ${px.coloured} pixels`);
  // Switching the method redraws without errors.
  const methods = await page.$$eval('#method option', (o) => o.map((x) => x.value));
  check(methods.length === names.length, 'every method can be shown: ' + methods);
  await page.selectOption('#method', methods[methods.length - 1]);
  check(errors.length === 0, 'no console errors after switching the method: ' + JSON.stringify(errors));
  await browser.close();
  console.log(failed ? `${failed} check(s) failed` : 'report page: all checks passed');
  process.exit(failed ? 1 : 0);
})().catch((e) => { console.log('FAIL: ' + e.stack); process.exit(1); });
