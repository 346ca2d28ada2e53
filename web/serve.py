#!/usr/bin/env python3
"""A small static web server with HTTP Range support, for the pomar web viewer.

    python3 web/serve.py [--root DIR] [--port 8000]      # serves DIR (default: the repository)

Binds to 127.0.0.1 only. GET/HEAD of files; a `Range: bytes=a-b` header gets 206 Partial
Content with Content-Range, several ranges (`bytes=a-b,c-d`) a multipart/byteranges body,
an unsatisfiable range 416. (Python's own
http.server ignores Range: it is no use for streaming.) `--test` adds what the browser
test needs: paths under /no-range/ are served ignoring Range (a server without Range
support), paths under /single-range/ answer a request for several ranges with 200 and the
whole file (as Amazon S3 does), POST /report/NAME stores the request body as NAME in --report-dir, and every
range served is logged (GET /log returns the log as JSON).
"""
import argparse
import json
import mimetypes
import os
import re
import sys
import threading
from http import HTTPStatus
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from urllib.parse import unquote, urlsplit

TYPES = {'.js': 'text/javascript', '.mjs': 'text/javascript', '.wasm': 'application/wasm',
         '.html': 'text/html; charset=utf-8', '.css': 'text/css', '.png': 'image/png',
         '.json': 'application/json', '.pomar': 'application/octet-stream'}


def parse_ranges(header, size):
    """[(start, end)] (inclusive) of a `Range: bytes=...` header for a file of `size` bytes,
    unsatisfiable ranges dropped ([]: none satisfiable, or a malformed header)."""
    if not header.strip().startswith('bytes='):
        return []
    out = []
    for spec in header.strip()[len('bytes='):].split(','):
        m = re.fullmatch(r'\s*(\d*)-(\d*)\s*', spec)
        if not m or (m.group(1) == '' and m.group(2) == ''):
            return []
        if m.group(1) == '':  # suffix range: the last N bytes
            start, end = max(0, size - int(m.group(2))), size - 1
        else:
            start = int(m.group(1))
            end = min(size - 1, int(m.group(2))) if m.group(2) else size - 1
        if start < size and start <= end:
            out.append((start, end))
    return out


class Handler(BaseHTTPRequestHandler):
    server_version = 'pomar-serve/1'

    def log_message(self, fmt, *args):
        if self.server.verbose:
            sys.stderr.write('serve: ' + fmt % args + '\n')

    def resolve(self):
        path = unquote(urlsplit(self.path).path)
        ignore_range = single_range = False
        if self.server.test and path.startswith('/no-range/'):
            path, ignore_range = path[len('/no-range'):], True
        if self.server.test and path.startswith('/single-range/'):
            path, single_range = path[len('/single-range'):], True
        full = os.path.normpath(os.path.join(self.server.root, path.lstrip('/')))
        inside = full == self.server.root or full.startswith(self.server.root + os.sep)
        if path.endswith('/'):
            full = os.path.join(full, 'index.html')
        return (full if inside else None), ignore_range, single_range

    def do_HEAD(self):
        self.do_GET(body=False)

    def do_GET(self, body=True):
        if self.server.test and self.path == '/log':
            self.reply(200, json.dumps(self.server.log).encode(), 'application/json', body)
            return
        full, ignore_range, single_range = self.resolve()
        if not full or not os.path.isfile(full):
            self.reply(404, b'not found\n', 'text/plain', body)
            return
        size = os.path.getsize(full)
        ctype = TYPES.get(os.path.splitext(full)[1]) or mimetypes.guess_type(full)[0] or 'application/octet-stream'
        header = self.headers.get('Range')
        ranges = None if not header or ignore_range else parse_ranges(header, size)
        if ranges == []:
            self.reply(416, b'', 'text/plain', body, {'Content-Range': f'bytes */{size}'})
            return
        if ranges and len(ranges) > 1 and single_range:
            ranges = None  # as S3 does: several ranges asked, the whole file sent
        extra = {'Accept-Ranges': 'bytes' if not ignore_range else 'none'}
        with open(full, 'rb') as f:
            if not ranges:
                parts = [(0, f.read())]
            else:
                parts = []
                for start, end in ranges:
                    f.seek(start)
                    parts.append((start, f.read(end - start + 1)))
        if self.server.test:
            with self.server.lock:
                for start, data in parts:
                    self.server.log.append({'path': self.path, 'status': 206 if ranges else 200, 'start': start,
                                            'bytes': len(data), 'parts': len(parts)})
        if not ranges:
            self.reply(200, parts[0][1], ctype, body, extra)
        elif len(parts) == 1:
            start, data = parts[0]
            extra['Content-Range'] = f'bytes {start}-{start + len(data) - 1}/{size}'
            self.reply(206, data, ctype, body, extra)
        else:  # several ranges: a multipart/byteranges body (RFC 9110 section 14.6)
            boundary = 'pomar-byteranges-' + os.urandom(8).hex()
            chunks = []
            for start, data in parts:
                chunks.append(f'\r\n--{boundary}\r\nContent-Type: {ctype}\r\n'
                              f'Content-Range: bytes {start}-{start + len(data) - 1}/{size}\r\n\r\n'.encode())
                chunks.append(data)
            chunks.append(f'\r\n--{boundary}--\r\n'.encode())
            self.reply(206, b''.join(chunks), f'multipart/byteranges; boundary={boundary}', body, extra)

    def do_POST(self):
        m = re.fullmatch(r'/report/([A-Za-z0-9_.-]+)', self.path)
        if not (self.server.test and self.server.report_dir and m):
            self.reply(404, b'not found\n', 'text/plain')
            return
        data = self.rfile.read(int(self.headers.get('Content-Length', '0')))
        tmp = os.path.join(self.server.report_dir, m.group(1) + '.part')
        with open(tmp, 'wb') as f:
            f.write(data)
        os.replace(tmp, os.path.join(self.server.report_dir, m.group(1)))
        self.reply(200, b'ok\n', 'text/plain')

    def reply(self, status, data, ctype, body=True, extra=None):
        self.send_response(status)
        self.send_header('Content-Type', ctype)
        self.send_header('Content-Length', str(len(data)))
        self.send_header('Cache-Control', 'no-store')
        for k, v in (extra or {}).items():
            self.send_header(k, v)
        self.end_headers()
        if body:
            try:
                self.wfile.write(data)
            except (BrokenPipeError, ConnectionResetError):
                pass  # the client cancelled (e.g. a 200 it did not want)


def make_server(root, port=0, test=False, report_dir=None, verbose=False):
    """A server on 127.0.0.1:port (0 = any free port); run it with serve_forever()."""
    server = ThreadingHTTPServer(('127.0.0.1', port), Handler)
    server.daemon_threads = True
    server.root = os.path.abspath(root)
    server.test = test
    server.report_dir = report_dir
    server.verbose = verbose
    server.log = []
    server.lock = threading.Lock()
    return server


def main():
    repo = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    ap = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    ap.add_argument('--root', default=repo, help='directory to serve (default: the repository)')
    ap.add_argument('--port', type=int, default=8000, help='port on 127.0.0.1 (0: any free port)')
    ap.add_argument('--quiet', action='store_true', help='do not log requests')
    args = ap.parse_args()
    server = make_server(args.root, args.port, verbose=not args.quiet)
    print(f'serving {server.root} at http://127.0.0.1:{server.server_address[1]}/ (Ctrl-C stops)', flush=True)
    try:
        server.serve_forever()
    except KeyboardInterrupt:
        pass


if __name__ == '__main__':
    main()
