// The web client's transport against a real server: node web/test/server_check.mjs URL FILE
// streams the .pomar file at URL (served by nginx, Apache, ... see real_servers.sh) and the
// same file read locally through the same code, and checks that the server's answers
// (multipart/byteranges or one range a request) give the same meshes at every step:
//   1. open (the global part);
//   2. four clusters at the finest level (scattered ranges: several per request);
//   3. every cluster at the finest level (the rest of the file).
// and that the file is fetched exactly once in all: bytes fetched = file size.
import { readFileSync } from 'node:fs';
import { PomarStream } from '../pomar_stream.js';
import { RangeFile } from '../range_fetch.js';
import { checker, loadModuleInNode } from './node_support.mjs';

const [url, path] = process.argv.slice(2);
if (!url || !path) {
  console.error('usage: node web/test/server_check.mjs URL FILE.pomar (FILE: the same file, read locally)');
  process.exit(2);
}
const { check, done } = checker();
const M = await loadModuleInNode();
const options = { maxGap: 128 }; // pomar.js's default
const remote = await new PomarStream(M, new RangeFile(url, options), options).open();
const local = await new PomarStream(M, new RangeFile(new Blob([readFileSync(path)]), options), options).open();

function same(a, b) {
  if (a.length !== b.length) return false;
  for (let i = 0; i < a.length; ++i) if (a[i] !== b[i]) return false;
  return true;
}
function compare(step) {
  const r = remote.decoder.mesh(), l = local.decoder.mesh();
  check(same(r.positions, l.positions), `${step}: positions differ from the local file's`);
  check(same(r.triangles, l.triangles), `${step}: triangles differ from the local file's`);
  check(same(remote.levels, local.levels), `${step}: levels differ from the local file's`);
  const s = remote.stats();
  console.log(`${step}: ${r.triangles.length / 3} triangles, ${s.bytesFetched} of ${s.fileBytes} bytes, ` +
    `${s.requests} requests for ${s.ranges} ranges, multipart answers: ${s.multiRange}`);
  return s;
}

const info = remote.info;
check(info.clusters > 0, 'the file has clusters (random access)');
compare('open');
const few = remote.baseLevels;
for (const k of [1, 2, 3, 4]) few[Math.floor((k * info.clusters) / 4.5)] = info.finestLevel;
await remote.want(few);
await local.want(few);
const partial = compare('four clusters at the finest level');
check(partial.bytesFetched < partial.fileBytes, 'four clusters read less than the file');
const all = new Int32Array(info.clusters).fill(info.finestLevel);
await remote.want(all);
await local.want(all);
const whole = compare('full resolution');
check(whole.bytesFetched === whole.fileBytes, `the whole file fetched exactly once (${whole.bytesFetched} bytes)`);
check(remote.warnings.length === 0, `no warning (${remote.warnings.join('; ')})`);
if (process.env.EXPECT_MULTIPART)
  check(whole.multiRange === true && whole.requests < whole.ranges, 'the server answered several ranges per request');
remote.close();
local.close();
done(`server_check ${url}`);
