#!/usr/bin/env python3
"""What truncated, misaligned and hostile .pomar files cost: time and memory.

    python3 bench/truncation_bench.py [--build DIR] [--data DIR] [--rounds N] [--quick]

Time: samples/bunny.ply encoded with `--clusters 6000` and `--clusters 10895` (and the
data folder's dragon.ply.xz with default options, when present), each cut at 40%, 60% and
80% of its bytes, and each whole and cut at 80% with its cluster index misaligned (the
middle cluster's block one byte longer and the last one byte shorter: every later block
is read one byte off, as `pomar_hostile_files shift-index` writes it). Each is decoded with
`pomar decode --skip-damaged --threads N` for N = 1, 2, 7, interleaved with the whole
file's decode on the same threads (A B A B ...), and the median times give the ratio
damaged / whole. The bound (docs/robustness.md): at most 1.5 times the whole file's
decode plus a few milliseconds.

Memory: the crafted hostile files of `pomar_hostile_files crafted` (huge claimed counts,
a zero-filled base block, 2^31 vertices, section tables at and past their limit, a zeroed
or misaligned cluster index; every file under 1 MB, checksums right), each through
`pomar info`, `pomar info --json` and `pomar info --check`: the peak RSS (GNU time's
maximum resident set size) and the exit status. The bound: under 64 MB, exit 4 (damaged) or 0.

Markdown on stdout, progress on stderr; exits 1 if a bound is exceeded.
"""
import argparse
import json
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)


def run(cmd, ok=(0,)):
    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if r.returncode not in ok:
        sys.exit('truncation_bench: %s failed (%d):\n%s%s' % (' '.join(cmd), r.returncode,
                                                             r.stdout, r.stderr))
    return r


def timed(cmd, ok):
    t = time.perf_counter()
    run(cmd, ok)
    return time.perf_counter() - t


def peak_rss(cmd):
    """(exit status, peak RSS in MiB) of cmd: GNU time's maximum resident set size when
    /usr/bin/time is there, else getrusage of a child of its own (which counts the pages
    of the Python process it is forked from: an upper bound)."""
    if os.path.exists('/usr/bin/time'):
        with tempfile.NamedTemporaryFile('r') as out:
            r = subprocess.run(['/usr/bin/time', '-f', '%M', '-o', out.name] + cmd,
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            return r.returncode, int(out.read().split()[-1]) / 1024.0
    probe = ('import resource, subprocess, sys\n'
             'r = subprocess.run(sys.argv[1:], stdout=subprocess.DEVNULL, '
             'stderr=subprocess.DEVNULL)\n'
             'print(r.returncode, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)\n')
    out = subprocess.run([sys.executable, '-c', probe] + cmd, stdout=subprocess.PIPE,
                         text=True, check=True).stdout.split()
    return int(out[0]), int(out[1]) / 1024.0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    ap.add_argument('--build', default=os.path.join(ROOT, 'build-test'))
    ap.add_argument('--pomar', help='the pomar tool to time (default: BUILD/codec/pomar)')
    ap.add_argument('--data', default=os.path.join(ROOT, '..', 'shared', 'data'))
    ap.add_argument('--rounds', type=int, default=5)
    ap.add_argument('--quick', action='store_true', help='bunny 6000 clusters only, 3 rounds')
    a = ap.parse_args()
    pomar = a.pomar or os.path.join(a.build, 'codec', 'pomar')
    tool = os.path.join(a.build, 'bench', 'pomar_hostile_files')
    for p in (pomar, tool):
        if not os.path.exists(p):
            sys.exit('truncation_bench: %s is missing (build the tree first)' % p)
    rounds = 3 if a.quick else a.rounds
    tmp = tempfile.mkdtemp(prefix='pomar-trunc-')
    failed = False
    try:
        inputs = [('bunny, 6000 clusters', os.path.join(ROOT, 'samples', 'bunny.ply'),
                   ['--clusters', '6000'])]
        if not a.quick:
            inputs.append(('bunny, 10895 clusters', inputs[0][1], ['--clusters', '10895']))
            dragon = os.path.join(a.data, 'dragon.ply.xz')
            if os.path.exists(dragon):
                ply = os.path.join(tmp, 'dragon.ply')
                with open(ply, 'wb') as out:
                    subprocess.run(['xz', '-dc', dragon], stdout=out, check=True)
                inputs.append(('dragon, default clusters', ply, []))
            else:
                print('truncation_bench: %s absent: the dragon is skipped' % dragon,
                      file=sys.stderr)
        print('| file | damage | threads | whole (s) | --skip-damaged (s) | ratio |')
        print('|:--|:--|--:|--:|--:|--:|')
        for label, mesh, options in inputs:
            whole = os.path.join(tmp, 'whole.pomar')
            run([pomar, 'encode', mesh, whole, '-q'] + options, ok=(0,))
            data = open(whole, 'rb').read()
            cases = []
            for kept in (0.4, 0.6, 0.8):
                path = os.path.join(tmp, 'cut%d.pomar' % int(kept * 100))
                with open(path, 'wb') as f:
                    f.write(data[:int(len(data) * kept)])
                cases.append(('cut at %d%%' % int(kept * 100), path))
            middle = str(json.loads(run([pomar, 'info', whole, '--json']).stdout)['clusters'] // 2)
            shifted = os.path.join(tmp, 'shifted.pomar')
            run([tool, 'shift-index', whole, shifted, middle, '1'])
            cases.append(('index misaligned after cluster %s' % middle, shifted))
            shifted_cut = os.path.join(tmp, 'shifted80.pomar')
            run([tool, 'shift-index', cases[2][1], shifted_cut, middle, '1'])
            cases.append(('cut at 80%%, misaligned after %s' % middle, shifted_cut))
            out = os.path.join(tmp, 'out.ply')
            for name, path in cases:
                for threads in (1, 2, 7):
                    t = ['--threads', str(threads)]
                    a_times, b_times = [], []
                    for _ in range(rounds):
                        a_times.append(timed([pomar, 'decode', whole, out, '-q'] + t, (0,)))
                        b_times.append(timed([pomar, 'decode', path, out, '-q',
                                              '--skip-damaged'] + t, (4,)))
                    ta, tb = statistics.median(a_times), statistics.median(b_times)
                    ratio = tb / ta
                    bad = tb > 1.5 * ta + 0.005
                    failed = failed or bad
                    print('| %s | %s | %d | %.3f | %.3f | %.2f%s |' %
                          (label, name, threads, ta, tb, ratio, ' **over**' if bad else ''))
                    sys.stdout.flush()
        # Memory of `pomar info` on crafted files.
        clustered = os.path.join(tmp, 'c.pomar')
        progressive = os.path.join(tmp, 'p.pomar')
        bunny = os.path.join(ROOT, 'samples', 'bunny.ply')
        run([pomar, 'encode', bunny, clustered, '-q'])
        run([pomar, 'encode', bunny, progressive, '-q', '--progressive'])
        crafted = os.path.join(tmp, 'crafted')
        os.mkdir(crafted)
        names = run([tool, 'crafted', clustered, progressive, crafted]).stdout.split()
        print()
        print('| crafted file | bytes | command | exit | peak RSS (MiB) |')
        print('|:--|--:|:--|--:|--:|')
        for name in names:
            path = os.path.join(crafted, name + '.pomar')
            for extra in ([], ['--json'], ['--check']):
                status, rss = peak_rss([pomar, 'info', path] + extra)
                bad = rss >= 64 or status not in (0, 4)
                failed = failed or bad
                print('| %s | %d | info %s | %d | %.1f%s |' %
                      (name, os.path.getsize(path), ' '.join(extra), status, rss,
                       ' **over**' if bad else ''))
    finally:
        shutil.rmtree(tmp)
    return 1 if failed else 0


if __name__ == '__main__':
    sys.exit(main())
