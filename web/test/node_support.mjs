// What the Node.js scripts of web/ (tests, bench) share: the WebAssembly module loaded in
// Node, and a counter of checks.
import { readFileSync } from 'node:fs';
import { createRequire } from 'node:module';
import { dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';
import { loadModule } from '../pomar_core.js';

/** web/dist/pomar_decoder.{mjs,wasm} instantiated in Node. Emscripten 3.1.6's ES module
 *  output looks for CommonJS globals there, and fetches the .wasm unless it is given. */
export function loadModuleInNode() {
  const dist = join(dirname(fileURLToPath(import.meta.url)), '..', 'dist');
  globalThis.require = createRequire(import.meta.url);
  globalThis.__dirname = dist;
  return loadModule({ wasmBinary: readFileSync(join(dist, 'pomar_decoder.wasm')) });
}

/** check(ok, what) prints FAIL lines; done(name) prints the count and exits 0 or 1. */
export function checker() {
  let checks = 0;
  let failures = 0;
  return {
    check(ok, what) {
      ++checks;
      if (!ok) {
        ++failures;
        console.error('FAIL: ' + what);
      }
    },
    get failures() {
      return failures;
    },
    done(name) {
      console.log(`${name}: ${checks} checks, ${failures} failed`);
      process.exit(failures ? 1 : 0);
    },
  };
}
