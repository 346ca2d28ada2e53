// Byte ranges of a remote file (HTTP Range requests) or of a local File/Blob: adjacent
// ranges are coalesced into one range, up to `maxRanges` ranges go in one request
// (`Range: bytes=a-b,c-d`, answered multipart/byteranges), at most `maxInFlight` requests
// run at once, and every failure is an Error whose message names the URL and the problem.
//
// Range planning. A server that answers several ranges in one request (nginx, Apache) gets
// the ranges of a step closer than `maxGap` joined and the rest batched. A server that
// answers one range a request (Amazon S3, most CDNs) makes every range a request: there
// the ranges of a step are planned with a cost model, each request costing
// `requestCost` bytes on top of the bytes it brings, so a gap is bridged exactly when it
// is shorter than `requestCost` (the cost is a sum over gaps: each gap is bridged or not
// on its own, and this rule gives the cheapest plan). In a file with a BLKO section the
// blocks lie in the Morton order of their clusters, so the blocks of one region are one
// run of the file and the plan reads it in a few requests.

export class RangeError_ extends Error {}

/** The cost of one request in bytes (range planning for servers that answer one range a
 *  request; web/README.md "Requests" has the trade-off it makes). */
export const DEFAULT_REQUEST_COST = 4096;

/** Coalesce byte ranges [{key, offset, size}] (any order) into requests
 *  [{offset, size, parts}] of adjacent ranges (gap <= maxGap bytes, at most maxBytes each
 *  unless one range alone is larger; a gap for which `skipGap(start, end)` is true, e.g.
 *  one holding bytes already at hand, is never bridged). */
export function coalesce(ranges, maxGap = 0, maxBytes = 1 << 20, skipGap = () => false) {
  const sorted = ranges.filter((r) => r.size > 0).sort((a, b) => a.offset - b.offset);
  const out = [];
  for (const r of sorted) {
    const last = out[out.length - 1];
    const end = r.offset + r.size;
    const gap = last ? r.offset - (last.offset + last.size) : Infinity;
    if (gap <= maxGap && end - last.offset <= maxBytes && (gap <= 0 || !skipGap(last.offset + last.size, r.offset))) {
      last.size = Math.max(last.size, end - last.offset);
      last.parts.push(r);
    } else {
      out.push({ offset: r.offset, size: r.size, parts: [r] });
    }
  }
  return out;
}

/** Index of `pattern` (bytes) in `bytes` from `from`, or -1. */
function indexOf(bytes, pattern, from) {
  const last = bytes.length - pattern.length;
  for (let i = Math.max(0, from); i <= last; ++i) {
    let k = 0;
    while (k < pattern.length && bytes[i + k] === pattern[k]) ++k;
    if (k === pattern.length) return i;
  }
  return -1;
}

/** The parts [{offset, bytes, total}] of a multipart/byteranges body (RFC 9110 14.6). The
 *  boundary is looked for only between parts: each part's bytes are skipped by length. */
export function parseByteranges(body, boundary, name = 'the file') {
  const delimiter = new TextEncoder().encode('--' + boundary);
  const blank = new TextEncoder().encode('\r\n\r\n');
  const bad = (what) => new RangeError_(`the server of ${name} sent a broken multipart/byteranges answer: ${what}`);
  const parts = [];
  for (let p = indexOf(body, delimiter, 0); ; ) {
    if (p < 0) throw bad('a delimiter is missing');
    p += delimiter.length;
    if (body[p] === 45 && body[p + 1] === 45) return parts; // "--": the closing delimiter
    const end = indexOf(body, blank, p);
    if (end < 0) throw bad('a part has no header end');
    const headers = new TextDecoder().decode(body.subarray(p, end));
    const m = /content-range:\s*bytes (\d+)-(\d+)\/(\d+|\*)/i.exec(headers);
    if (!m) throw bad('a part has no Content-Range');
    const from = end + blank.length;
    const length = Number(m[2]) - Number(m[1]) + 1;
    if (from + length > body.length) throw bad(`a part of ${length} bytes is cut short`);
    parts.push({ offset: Number(m[1]), bytes: body.subarray(from, from + length), total: m[3] });
    p = indexOf(body, delimiter, from + length);
  }
}

export class RangeFile {
  /** `source`: a URL (string) or a File/Blob. */
  constructor(source, { maxInFlight = 4, maxGap = 0, maxRequestBytes = 1 << 20, maxRanges = 100,
    requestCost = DEFAULT_REQUEST_COST } = {}) {
    this.source = source;
    this.name = typeof source === 'string' ? source : source.name || 'local file';
    this.maxInFlight = maxInFlight;
    this.maxGap = maxGap;
    this.requestCost = requestCost;
    this.maxRequestBytes = maxRequestBytes;
    this.maxRanges = maxRanges;
    // Does the server answer several ranges in one request? null: not asked yet (the
    // first such request is a probe: the others wait for it).
    this.multiRange = maxRanges > 1 ? null : false;
    this.probe = null;
    this.size = typeof source === 'string' ? -1 : source.size;
    this.stats = { requests: 0, ranges: 0, bytesFetched: 0, inFlight: 0, maxInFlightSeen: 0 };
    this.waiting = [];
  }

  async slot() {
    if (this.stats.inFlight >= this.maxInFlight)
      await new Promise((resolve) => this.waiting.push(resolve));
    ++this.stats.inFlight;
    this.stats.maxInFlightSeen = Math.max(this.stats.maxInFlightSeen, this.stats.inFlight);
  }
  release() {
    --this.stats.inFlight;
    const next = this.waiting.shift();
    if (next) next();
  }

  /** Bytes [offset, offset + size) (fewer at the end of the file). Learns the file size
   *  from the first response (Content-Range). */
  async read(offset, size) {
    await this.slot();
    try {
      return await this.readNow(offset, size);
    } finally {
      this.release();
    }
  }

  async readNow(offset, size) {
    ++this.stats.requests;
    ++this.stats.ranges;
    if (typeof this.source !== 'string') {
      const end = Math.min(this.size, offset + size);
      const bytes = new Uint8Array(await this.source.slice(offset, end).arrayBuffer());
      this.stats.bytesFetched += bytes.length;
      return bytes;
    }
    let response;
    try {
      response = await fetch(this.source, { headers: { Range: `bytes=${offset}-${offset + size - 1}` } });
    } catch (e) {
      throw new RangeError_(`cannot fetch ${this.name}: ${e.message || e}`);
    }
    if (response.status === 416) {
      // Past the end: only possible for a file shorter than its own header says.
      const total = /\/(\d+)$/.exec(response.headers.get('Content-Range') || '');
      if (total) this.size = Number(total[1]);
      await response.body?.cancel();
      return new Uint8Array(0);
    }
    if (response.status === 200) {
      await response.body?.cancel();
      throw new RangeError_(`the server of ${this.name} ignores HTTP Range requests (it answered ` +
        `200 with the whole file): streaming needs a server with Range support`);
    }
    if (response.status !== 206) {
      await response.body?.cancel();
      throw new RangeError_(`cannot fetch ${this.name}: HTTP ${response.status} ${response.statusText}`.trim());
    }
    const range = /^bytes (\d+)-(\d+)\/(\d+|\*)$/.exec(response.headers.get('Content-Range') || '');
    if (!range || Number(range[1]) !== offset)
      throw new RangeError_(`the server of ${this.name} answered a range request with a wrong ` +
        `Content-Range (${response.headers.get('Content-Range')})`);
    if (range[3] !== '*') this.size = Number(range[3]);
    let bytes;
    try {
      bytes = new Uint8Array(await response.arrayBuffer());
    } catch (e) {
      throw new RangeError_(`the download of ${this.name} broke off: ${e.message || e}`);
    }
    this.stats.bytesFetched += bytes.length;
    if (bytes.length !== Number(range[2]) - offset + 1)
      throw new RangeError_(`the server of ${this.name} sent ${bytes.length} bytes for a range of ` +
        `${Number(range[2]) - offset + 1}`);
    return bytes;
  }

  /** Several ranges [{offset, size}] in one request: the chunks [{offset, bytes}] the server
   *  sent ([] when it does not answer several ranges in one request: then
   *  this.multiRange = false and the caller asks them one by one). */
  async readRanges(batch) {
    if (this.multiRange === null && this.probe) await this.probe;
    if (this.multiRange === false) return [];
    const request = (async () => {
      await this.slot();
      try {
        return await this.readRangesNow(batch);
      } finally {
        this.release();
      }
    })();
    if (this.multiRange === null) this.probe = request.catch(() => {});
    return request;
  }

  async readRangesNow(batch) {
    ++this.stats.requests;
    this.stats.ranges += batch.length;
    if (typeof this.source !== 'string') {
      // A local file: each range sliced, counted as the one request a server would get.
      const chunks = [];
      for (const r of batch) {
        const bytes = new Uint8Array(await this.source.slice(r.offset, r.offset + r.size).arrayBuffer());
        this.stats.bytesFetched += bytes.length;
        chunks.push({ offset: r.offset, bytes });
      }
      this.multiRange = true;
      return chunks;
    }
    const spec = batch.map((r) => `${r.offset}-${r.offset + r.size - 1}`).join(',');
    let response;
    try {
      response = await fetch(this.source, { headers: { Range: `bytes=${spec}` } });
    } catch (e) {
      // Cross-origin, such a Range header needs a CORS preflight the server may refuse.
      if (this.multiRange !== null) throw new RangeError_(`cannot fetch ${this.name}: ${e.message || e}`);
      this.multiRange = false;
      return [];
    }
    const boundary = /multipart\/byteranges;\s*boundary="?([^";]+)"?/i.exec(response.headers.get('Content-Type') || '');
    if (response.status === 206 && boundary) {
      let body;
      try {
        body = new Uint8Array(await response.arrayBuffer());
      } catch (e) {
        throw new RangeError_(`the download of ${this.name} broke off: ${e.message || e}`);
      }
      const chunks = parseByteranges(body, boundary[1], this.name);
      for (const c of chunks) {
        this.stats.bytesFetched += c.bytes.length;
        if (c.total !== '*') this.size = Number(c.total);
      }
      this.multiRange = true;
      return chunks;
    }
    // Anything else (200 with the whole file, as Amazon S3 answers; one range only): one
    // range a request from now on, this answer dropped unread.
    await response.body?.cancel();
    this.multiRange = false;
    return [];
  }

  /** Coalesced requests grouped by consecutive runs of up to maxRanges ranges and
   *  maxRequestBytes bytes (each group one request when the server answers several ranges). */
  batches(requests) {
    const out = [];
    for (const req of requests) {
      const last = out[out.length - 1];
      if (last && this.multiRange !== false && last.length < this.maxRanges && last.bytes + req.size <= this.maxRequestBytes) {
        last.push(req);
        last.bytes += req.size;
      } else {
        out.push(Object.assign([req], { bytes: req.size }));
      }
    }
    return out;
  }

  /** The requests [{offset, size, parts}] for `ranges`, clipped to the file: for a server
   *  answering several ranges a request, gaps up to maxGap bridged except those holding
   *  bytes at hand (`skipGap`); one range a request (`oneRange`), gaps shorter than
   *  requestCost bridged, whatever they hold (a request costs more than those bytes). */
  plan(ranges, oneRange, skipGap) {
    const gap = oneRange ? Math.max(this.maxGap, this.requestCost) : this.maxGap;
    const requests = [];
    for (const req of coalesce(ranges, gap, this.maxRequestBytes, oneRange ? () => false : skipGap)) {
      if (this.size >= 0) req.size = Math.max(0, Math.min(this.size, req.offset + req.size) - req.offset);
      requests.push(req);
    }
    return requests;
  }

  /** Fetch ranges [{key, offset, size}], planned (plan) and batched, at most maxInFlight
   *  requests at once. The first request of several ranges probes the server; when it
   *  answers one range a request, what that request asked for and everything after is
   *  planned again for one range a request. Returns {parts: Map key -> Uint8Array (shorter
   *  than asked at the end of a truncated file) or Error (that request failed), chunks:
   *  [{offset, bytes}] (every range received, bridged gaps included)}. */
  async readMany(ranges, skipGap = () => false) {
    const parts = new Map();
    const chunks = [];
    const fill = (req, chunk) => {
      for (const p of req.parts) {
        if (chunk instanceof Error) {
          parts.set(p.key, chunk);
          continue;
        }
        const a = Math.min(chunk.bytes.length, p.offset - chunk.offset);
        parts.set(p.key, chunk.bytes.subarray(a, Math.min(chunk.bytes.length, a + p.size)));
      }
    };
    const one = async (req) => {
      if (req.size <= 0) {
        fill(req, { offset: req.offset, bytes: new Uint8Array(0) });
        return;
      }
      let chunk;
      try {
        chunk = { offset: req.offset, bytes: await this.read(req.offset, req.size) };
      } catch (e) {
        fill(req, e);
        return;
      }
      chunks.push(chunk);
      fill(req, chunk);
    };
    const oneByOne = (list) => Promise.all(this.plan(list, true, skipGap).map(one));
    if (this.multiRange === false) {
      await oneByOne(ranges);
      return { parts, chunks };
    }
    const covers = (c, req) => c.offset <= req.offset && c.offset + c.bytes.length >= req.offset + req.size;
    const again = []; // ranges of batches the server answered otherwise: one range a request
    const requests = [];
    for (const req of this.plan(ranges, false, skipGap)) {
      if (req.size > 0) requests.push(req);
      else fill(req, { offset: req.offset, bytes: new Uint8Array(0) });
    }
    await Promise.all(this.batches(requests).map(async (batch) => {
      if (batch.length === 1) {
        await one(batch[0]);
        return;
      }
      let got;
      try {
        got = await this.readRanges(batch);
      } catch (e) {
        batch.forEach((req) => fill(req, e));
        return;
      }
      chunks.push(...got);
      for (const req of batch) {
        const chunk = got.find((c) => covers(c, req));
        if (chunk) fill(req, chunk);
        else again.push(...req.parts);
      }
    }));
    if (again.length) await oneByOne(again);
    return { parts, chunks };
  }
}
