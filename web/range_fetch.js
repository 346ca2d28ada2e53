// Byte ranges of a remote file (HTTP Range requests) or of a local File/Blob: adjacent
// ranges are coalesced into one request, at most `maxInFlight` requests run at once, and
// every failure is an Error whose message names the URL and the problem.

export class RangeError_ extends Error {}

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

export class RangeFile {
  /** `source`: a URL (string) or a File/Blob. */
  constructor(source, { maxInFlight = 4, maxGap = 0, maxRequestBytes = 1 << 20 } = {}) {
    this.source = source;
    this.name = typeof source === 'string' ? source : source.name || 'local file';
    this.maxInFlight = maxInFlight;
    this.maxGap = maxGap;
    this.maxRequestBytes = maxRequestBytes;
    this.size = typeof source === 'string' ? -1 : source.size;
    this.stats = { requests: 0, bytesFetched: 0, inFlight: 0, maxInFlightSeen: 0 };
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

  /** Fetch ranges [{key, offset, size}], coalesced, at most maxInFlight requests at once.
   *  Returns {parts: Map key -> Uint8Array (shorter than asked at the end of a truncated
   *  file) or Error (that request failed), chunks: [{offset, bytes}] (every response, gaps
   *  between coalesced ranges included)}. */
  async readMany(ranges, skipGap = undefined) {
    const parts = new Map();
    const chunks = [];
    const requests = coalesce(ranges, this.maxGap, this.maxRequestBytes, skipGap);
    await Promise.all(requests.map(async (req) => {
      try {
        const end = this.size >= 0 ? Math.min(this.size, req.offset + req.size) : req.offset + req.size;
        const bytes = end > req.offset ? await this.read(req.offset, end - req.offset) : new Uint8Array(0);
        chunks.push({ offset: req.offset, bytes });
        for (const p of req.parts) {
          const a = Math.min(bytes.length, p.offset - req.offset);
          parts.set(p.key, bytes.subarray(a, Math.min(bytes.length, a + p.size)));
        }
      } catch (e) {
        for (const p of req.parts) parts.set(p.key, e);
      }
    }));
    return { parts, chunks };
  }
}
