// Streaming decode of one .pomar file: what to fetch for a wanted level map, and decoding it.
// Used by the Web Worker (pomar_worker.js), the Node tests and the bench; knows nothing of
// workers or the page. `file` is a RangeFile (range_fetch.js) over a URL or a Blob.
//
// Each cluster block is held as a prefix: a cluster wanted at level l < finest needs only
// the start of its block (its levels are coded one after the other), estimated from the
// level table's vertex counts with a margin; the finest level needs the whole block, and
// small blocks (wholeBlockBytes) are fetched whole at once. If the
// estimate was short, the decoder reports the cluster whose bytes were missing; the rest
// of that block is fetched, the streams are reset (everything coarsened to the base
// clustered level, nothing fetched) and the level map decoded again. Damage (a block that
// fails its check or does not decode, a truncated file, a failed fetch) switches the stream
// to tolerant mode for good: whole blocks, damaged ones skipped as --skip-damaged does.
import { Decoder, PomarError, globalBytes, layoutOf, previewMesh } from './pomar_core.js';

function concat(a, b) {
  const out = new Uint8Array(a.length + b.length);
  out.set(a);
  out.set(b, a.length);
  return out;
}

export class PomarStream {
  /** options: firstRequestBytes (16 KiB), memoryBudget (bytes of blocks held; over it the
   *  decoder is rebuilt with only what the current level map needs), tolerant (start in
   *  tolerant mode), estimateMargin (1.25), estimateSlack (16 bytes), wholeBlockBytes (0). */
  constructor(M, file, options = {}) {
    this.M = M;
    this.file = file;
    this.options = options;
    this.tolerant = !!options.tolerant;
    this.rebuilds = 0;
    this.retries = 0;
    this.warnings = [];
  }

  /** Read the global part and decode the base clustered mesh. `onPreview(mesh, stats)`,
   *  when given, gets the first frames while the global part is still arriving: the base
   *  mesh and the global levels at hand once the first request is in, the last global level
   *  once the levels are in (previewMesh: positions and triangles). */
  async open(onPreview = null) {
    const file = this.file;
    let prefix = await file.read(0, this.options.firstRequestBytes || 16384);
    if (prefix.length === 0) throw new PomarError(`${file.name} is empty`);
    for (let need; (need = globalBytes(this.M, prefix, file.size)) > prefix.length;) {
      const layout = layoutOf(this.M, prefix, file.size); // null: the header is not all in yet
      if (!layout || !onPreview) {
        prefix = concat(prefix, await file.read(prefix.length, need - prefix.length));
        continue;
      }
      prefix = await this.readGlobal(prefix, layout, onPreview);
      break;
    }
    this.prefix = prefix;
    try {
      this.decoder = new Decoder(this.M, prefix, file.size, this.tolerant);
    } catch (e) {
      // A file cut short in its cluster blocks opens only in tolerant mode.
      if (this.tolerant || !(e instanceof PomarError)) throw e;
      this.decoder = new Decoder(this.M, prefix, file.size, (this.tolerant = true));
      this.warnings.push(`${e.message}: decoding around the missing blocks`);
    }
    const d = this.decoder;
    this.info = d.info;
    const n = this.info.clusters;
    this.have = new Float64Array(n); // bytes held of each block (a prefix)
    this.blocks = new Array(n).fill(null);
    this.whole = new Set(); // blocks whose estimate fell short: fetched whole from then on
    this.heldBytes = 0;
    this.byOffset = Array.from({ length: n }, (_, c) => c).sort((a, b) => d.blockOffset[a] - d.blockOffset[b]);
    this.levels = new Int32Array(n).fill(this.info.baseLevel);
    this.absorb([{ offset: 0, bytes: prefix }]).forEach((c) => this.put(c));
    return this;
  }

  /** The rest of the global part after its first bytes `prefix`, drawing as it comes: the
   *  base mesh (fetched first if the first request did not hold it) with the global levels
   *  at hand, then, in a file whose sections (stored errors, attributes) lie between the
   *  base mesh and the levels, the levels, model tables and cluster index in one request
   *  while the sections come in another, so the last global level is drawn before the
   *  sections are in. */
  async readGlobal(prefix, layout, onPreview) {
    const file = this.file;
    const all = new Uint8Array(layout.globalBytes);
    all.set(prefix);
    let have = prefix.length;
    if (layout.baseEnd > have) {
      all.set(await file.read(have, layout.baseEnd - have), have);
      have = layout.baseEnd;
    }
    const show = (upto) => {
      // The levels decodable from the bytes [0, upto) and [levelStart, upto).
      const attr = layout.attrEnd <= upto || layout.attrEnd === 0;
      let levels = 0;
      while (attr && levels < layout.levelEnds.length && layout.levelEnds[levels] <= upto) ++levels;
      try {
        const mesh = previewMesh(this.M, all.subarray(0, levels ? layout.levelEnds[levels - 1] : layout.baseEnd), file.size, levels);
        onPreview(mesh, { ...this.file.stats, fileBytes: file.size });
      } catch (e) {
        // A damaged base mesh or level: the decoder opened next names it.
        if (!(e instanceof PomarError)) throw e;
      }
    };
    show(have);
    // (Sections of a few bytes, such as BLKO's, are not worth a request of their own.)
    const split = layout.levelStart > have + 64 && layout.attrStart === 0;
    if (!split) {
      const rest = await file.read(have, layout.globalBytes - have);
      all.set(rest, have);
      return all.subarray(0, have + rest.length); // (shorter: a truncated file)
    }
    // The sections between the base mesh and the levels (stored errors) in parallel.
    const pending = file.read(have, layout.levelStart - have);
    pending.catch(() => {}); // (a failure is thrown below, once the levels are awaited)
    const levels = await file.read(layout.levelStart, layout.globalBytes - layout.levelStart);
    all.set(levels, layout.levelStart);
    if (levels.length === layout.globalBytes - layout.levelStart) show(layout.globalBytes);
    const sections = await pending;
    all.set(sections, have);
    if (sections.length < layout.levelStart - have) return all.subarray(0, have + sections.length);
    return all.subarray(0, layout.levelStart + levels.length);
  }

  get baseLevels() {
    return new Int32Array(this.info.clusters).fill(this.info.baseLevel);
  }

  /** Bytes of block c to hold for decoding it to `level`: the whole block, or, for a block
   *  larger than `wholeBlockBytes` (default 0) wanted below the finest level, an estimate of
   *  its prefix (the share of the level table's vertex splits up to that level, with a
   *  margin). A prefix that fell short once is fetched whole from then on. */
  need(c, level) {
    const { baseLevel: base, finestLevel: finest, levels } = this.info;
    const size = this.decoder.blockSize[c];
    if (level <= base) return 0;
    const small = size <= (this.options.wholeBlockBytes ?? 0);
    if (this.tolerant || level >= finest || this.whole.has(c) || small) return size;
    const vertices = (l) => (l === 0 ? this.info.baseVertices : levels[l - 1].vertices);
    const share = (vertices(level) - vertices(base)) / (vertices(finest) - vertices(base));
    const slack = this.options.estimateSlack ?? 16;
    const estimate = Math.min(size, Math.ceil(size * share * (this.options.estimateMargin || 1.25)) + slack);
    return Math.max(estimate, this.have[c]);
  }

  /** Position in byOffset of the first block starting at or after `offset`. */
  firstBlockFrom(offset) {
    const off = this.decoder.blockOffset;
    let lo = 0;
    let hi = this.byOffset.length;
    while (lo < hi) {
      const mid = (lo + hi) >> 1;
      if (off[this.byOffset[mid]] < offset) lo = mid + 1;
      else hi = mid;
    }
    return lo;
  }

  /** The blocks overlapping [start, end), in file order. */
  *blocksIn(start, end) {
    const off = this.decoder.blockOffset;
    const size = this.decoder.blockSize;
    let i = this.firstBlockFrom(start);
    if (i > 0 && off[this.byOffset[i - 1]] + size[this.byOffset[i - 1]] > start) --i;
    for (; i < this.byOffset.length && off[this.byOffset[i]] < end; ++i) yield this.byOffset[i];
  }

  /** Does [start, end) hold bytes already at hand? Such gaps are not bridged by a request. */
  haveSome(start, end) {
    if (start < this.prefix.length) return true;
    for (const c of this.blocksIn(start, end)) {
      const off = this.decoder.blockOffset[c];
      if (this.have[c] > 0 && off < end && off + this.have[c] > start) return true;
    }
    return false;
  }

  /** Extend the held prefixes with fetched bytes that continue them (a response may also
   *  bring blocks nobody asked for yet: the gaps of coalesced requests). Returns the
   *  clusters whose prefix grew. */
  absorb(chunks) {
    const grown = new Set();
    const off = this.decoder.blockOffset;
    const size = this.decoder.blockSize;
    for (const { offset, bytes } of chunks) {
      const end = offset + bytes.length;
      for (const c of this.blocksIn(offset, end)) {
        const from = off[c] + this.have[c];
        if (this.have[c] >= size[c] || from < offset || from >= end) continue;
        const upto = Math.min(off[c] + size[c], end);
        const more = bytes.subarray(from - offset, upto - offset);
        this.blocks[c] = this.blocks[c] ? concat(this.blocks[c], more) : more.slice();
        this.have[c] += more.length;
        this.heldBytes += more.length;
        grown.add(c);
      }
    }
    return grown;
  }

  put(c) {
    this.decoder.putBlock(c, this.blocks[c].subarray(0, this.have[c]));
  }

  /** Fetch what `target` (a completed level map) needs and hand it over. Returns the
   *  messages of failed requests. */
  async fetchFor(target) {
    const base = this.info.baseLevel;
    const off = this.decoder.blockOffset;
    const ranges = [];
    for (let c = 0; c < target.length; ++c) {
      const n = target[c] > base ? this.need(c, target[c]) : 0;
      if (this.have[c] < n) ranges.push({ key: c, offset: off[c] + this.have[c], size: n - this.have[c] });
    }
    if (!ranges.length) return [];
    const { parts, chunks } = await this.file.readMany(ranges, (a, b) => this.haveSome(a, b));
    for (const c of this.absorb(chunks)) this.put(c);
    const failed = [];
    for (const part of parts.values()) if (part instanceof Error) failed.push(part.message);
    return failed;
  }

  /** Decode to the level map completed from `levels` (one per cluster; progressive files:
   *  [level]), fetching what is missing. Returns the level of every cluster. */
  async want(levels) {
    const d = this.decoder;
    if (this.info.clusters === 0) {
      try {
        this.levels = d.update(levels);
      } catch (e) {
        // A damaged global level: decode up to the level before it, as --skip-damaged does.
        if (this.tolerant || !(e instanceof PomarError)) throw e;
        return this.becomeTolerant(levels);
      }
      return this.levels;
    }
    const target = d.complete(levels);
    const failed = await this.fetchFor(target);
    if (failed.length) {
      this.warnings.push(`${failed.length} block requests failed: ${failed[0]}`);
      if (!this.tolerant) return this.becomeTolerant(levels);
    }
    for (let attempt = 0; ; ++attempt) {
      try {
        this.levels = this.decoder.update(levels);
        break;
      } catch (e) {
        if (!(e instanceof PomarError) || this.tolerant) throw e;
        if (e.missingCluster >= 0 && attempt < target.length) {
          // The estimate fell short: the rest of that block, then decode again.
          ++this.retries;
          this.whole.add(e.missingCluster);
          this.decoder.update(this.baseLevels);
          const again = await this.fetchFor(target);
          if (!again.length) continue;
          this.warnings.push(`block requests failed: ${again[0]}`);
        }
        return this.becomeTolerant(levels);
      }
    }
    if (this.options.memoryBudget && this.heldBytes > this.options.memoryBudget) this.rebuild(levels);
    return this.levels;
  }

  /** Damage or a failed fetch: from now on whole blocks, damaged ones skipped. */
  async becomeTolerant(levels) {
    this.tolerant = true;
    await this.fetchFor(this.decoder.complete(levels));
    this.rebuild(levels);
    return this.levels;
  }

  /** A new decoder from the global part, given the blocks the level map of `levels` needs
   *  (the others are dropped: the memory budget), decoded to that map. */
  rebuild(levels) {
    ++this.rebuilds;
    const target = this.decoder.complete(levels);
    this.decoder.close();
    this.decoder = new Decoder(this.M, this.prefix, this.file.size, this.tolerant);
    for (let c = 0; c < target.length; ++c) {
      if (target[c] > this.info.baseLevel && this.have[c] > 0) {
        this.put(c);
      } else if (this.have[c] > 0 && this.decoder.blockOffset[c] >= this.prefix.length) {
        this.heldBytes -= this.have[c];
        this.have[c] = 0;
        this.blocks[c] = null;
      }
    }
    this.levels = this.decoder.update(levels);
  }

  stats() {
    const f = this.file.stats;
    let blocksHeld = 0;
    for (let c = 0; c < this.info.clusters; ++c) blocksHeld += this.have[c] > 0;
    return { fileBytes: this.file.size, bytesFetched: f.bytesFetched, requests: f.requests, ranges: f.ranges,
      multiRange: this.file.multiRange, maxInFlightSeen: f.maxInFlightSeen, blocksHeld, heldBytes: this.heldBytes, rebuilds: this.rebuilds,
      retries: this.retries, tolerant: this.tolerant, damaged: this.decoder.damaged().count };
  }

  close() {
    if (this.decoder) this.decoder.close();
    this.decoder = null;
  }
}
