#!/usr/bin/env python3
"""Issue 32's targets for mesh(file: ...), written to bench/results/mesh_in.md.

Meshes are made here (a latitude-longitude sphere of radius 1 as binary STL,
2 * rings * segments triangles), never stored. Each figure is the median of
alternating runs (mesh, sphere, mesh, ...), since the machine is shared.

  python3 bench/mesh_in.py --sdfc build/cli/sdfc [--runs 3] [--skip-million]
"""
import argparse, math, os, re, statistics, struct, subprocess, sys, tempfile, time

def sphere_stl(path, rings, segments):
    tris = []
    def p(i, j):
        th, ph = math.pi * i / rings, 2 * math.pi * j / segments
        return (math.sin(th) * math.cos(ph), math.cos(th), math.sin(th) * math.sin(ph))
    with open(path, 'wb') as f:
        f.write(b'\0' * 80)
        count = 0
        body = bytearray()
        for i in range(rings):
            for j in range(segments):
                a, b, c, d = p(i, j), p(i + 1, j), p(i + 1, j + 1), p(i, j + 1)
                for t in ((a, c, b), (a, d, c)):  # counter-clockwise seen from outside
                    body += struct.pack('<12fH', 0, 0, 0, *t[0], *t[1], *t[2], 0)
                    count += 1
        f.write(struct.pack('<I', count))
        f.write(body)
    return count

SCENE = """render(size: [640, 360], spp: 1, bounces: 2)
camera(position: [0, 0.6, 4], target: [0, 0, 0], fov: 40)
let clay = diffuse(albedo: [0.8, 0.3, 0.25])
scene {{
  {shape}
  plane(normal: [0, 1, 0], offset: -1)
}}
"""

CPU = {}  # command name -> CPU seconds (user + sys) of each run

def timed(cmd, stdin=None, key=None):
    """Wall seconds and peak resident KB of one run (GNU time); its CPU seconds into CPU[key]."""
    t = subprocess.run(['/usr/bin/time', '-f', '%e %M %U %S'] + cmd, input=stdin, capture_output=True, check=True)
    wall, kb, user, sys_ = t.stderr.decode().strip().splitlines()[-1].split()
    if key:
        CPU.setdefault(key, []).append(float(user) + float(sys_))
    return float(wall), int(kb), t.stdout

def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('--sdfc', required=True)
    ap.add_argument('--runs', type=int, default=3)
    ap.add_argument('--skip-million', action='store_true')
    ap.add_argument('--points', type=int, default=1000000, help='eval points (issue: 1M)')
    a = ap.parse_args()
    sdfc = os.path.abspath(a.sdfc)
    d = tempfile.mkdtemp(prefix='sdfc mesh_in ')
    lines = ['# mesh(file: ...): issue 32\'s targets', '',
             'bench/mesh_in.py; medians of %d alternating runs; %s' % (a.runs, time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())),
             'load average at the start: %.1f (2 cores shared)' % os.getloadavg()[0], '']
    sizes = [('100k', 250, 200)] + ([] if a.skip_million else [('1M', 1000, 500)])
    with open(os.path.join(d, 'sphere.sdf'), 'w') as f:
        f.write(SCENE.format(shape='sphere(radius: 1, material: clay)'))
    for name, rings, segs in sizes:
        n = sphere_stl(os.path.join(d, name + '.stl'), rings, segs)
        scene = os.path.join(d, name + '.sdf')
        with open(scene, 'w') as f:
            f.write(SCENE.format(shape='mesh(file: "%s.stl", material: clay)' % name))
        check, comp, render_m, render_s, render_x, mem = [], [], [], [], [], []
        render_mw, render_sw = [], []
        CPU.clear()
        for _ in range(a.runs):
            w, kb, _ = timed([sdfc, 'check', scene], key='check'); check.append(w)
            w, kb, _ = timed([sdfc, 'compile', '--no-cache', '--emit', 'glsl', scene, '-o', os.devnull], key='compile'); comp.append(w); mem.append(kb)
            w, _, _ = timed([sdfc, 'render', '--no-cache', '--denoise', 'none', scene, '-o', os.path.join(d, name + '.png')], key='mesh'); render_m.append(w)
            w, _, _ = timed([sdfc, 'render', '--no-cache', '--denoise', 'none', os.path.join(d, 'sphere.sdf'), '-o', os.path.join(d, 's.png')], key='sphere'); render_s.append(w)
            # With sdfc's own caches (SPIR-V, mesh grid) warm, as a user's second
            # render or a viewer save that leaves the mesh file alone.
            warm = dict(os.environ, XDG_CACHE_HOME=os.path.join(d, 'cache'))
            for key, sc, out in (('mesh warm', scene, name + ' w.png'), ('sphere warm', os.path.join(d, 'sphere.sdf'), 's w.png')):
                cmd = [sdfc, 'render', '--denoise', 'none', sc, '-o', os.path.join(d, out)]
                subprocess.run(cmd, env=warm, capture_output=True, check=True)
                t = subprocess.run(['/usr/bin/time', '-f', '%e %M %U %S'] + cmd, env=warm, capture_output=True, check=True)
                wall, _, user, sys_ = t.stderr.decode().strip().splitlines()[-1].split()
                CPU.setdefault(key, []).append(float(user) + float(sys_))
                (render_mw if key == 'mesh warm' else render_sw).append(float(wall))
            if name == '100k':
                w, _, _ = timed([sdfc, 'render', '--no-cache', '--denoise', 'none', '--mesh-mode', 'exact', scene, '-o', os.path.join(d, name + ' exact.png')], key='exact'); render_x.append(w)
        med = statistics.median
        cpu = lambda k: '%.2f' % med(CPU[k])
        lines += ['## %s triangles (%d)' % (name, n), '',
                  '| measure | median wall (s) | median CPU (s) | runs (wall) |', '|---|---|---|---|',
                  '| check (read, weld, hierarchy) | %.2f | %s | %s |' % (med(check), cpu('check'), ' '.join('%.2f' % x for x in check)),
                  '| compile to GLSL (check + grid build + emit) | %.2f | %s | %s |' % (med(comp), cpu('compile'), ' '.join('%.2f' % x for x in comp)),
                  '| peak memory of compile | %.0f MB | | |' % (max(mem) / 1024),
                  '| first image 640x360 1 spp, whole process (default mode) | %.2f | %s | %s |' % (med(render_m), cpu('mesh'), ' '.join('%.2f' % x for x in render_m)),
                  '| the same with sphere(radius: 1) | %.2f | %s | %s |' % (med(render_s), cpu('sphere'), ' '.join('%.2f' % x for x in render_s)),
                  '| ratio mesh / sphere | %.2f | %.2f | |' % (med(render_m) / med(render_s), med(CPU['mesh']) / med(CPU['sphere'])),
                  '| first image, sdfc\'s caches warm (SPIR-V, mesh grid) | %.2f | %s | %s |' % (med(render_mw), cpu('mesh warm'), ' '.join('%.2f' % x for x in render_mw)),
                  '| the same with sphere(radius: 1) | %.2f | %s | %s |' % (med(render_sw), cpu('sphere warm'), ' '.join('%.2f' % x for x in render_sw)),
                  '| ratio mesh / sphere, caches warm | %.2f | %.2f | |' % (med(render_mw) / med(render_sw), med(CPU['mesh warm']) / med(CPU['sphere warm']))]
        if render_x:
            lines += ['| first image, --mesh-mode exact | %.2f | %s | %s |' % (med(render_x), cpu('exact'), ' '.join('%.2f' % x for x in render_x))]
        lines += ['']
        if name == '100k':
            pts = os.path.join(d, 'points.txt')
            import random
            random.seed(1)
            with open(pts, 'w') as f:
                for _ in range(a.points):
                    f.write('%.4f %.4f %.4f\n' % (random.uniform(-1.5, 1.5), random.uniform(-1.5, 1.5), random.uniform(-1.5, 1.5)))
            # One run: the evaluator is single-threaded and the figure is long.
            w, _, _ = timed([sdfc, 'eval', scene, '--points', pts])
            lines += ['eval of %d random points in [-1.5, 1.5]^3 (float64, signed, one thread): %.1f s wall including the check and printing: %.0f points/s' % (a.points, w, a.points / (w - med(check))), '']
    out = os.path.join(os.path.dirname(os.path.abspath(__file__)), 'results', 'mesh_in.md')
    with open(out, 'w') as f:
        f.write('\n'.join(lines) + '\n')
    print('\n'.join(lines))

if __name__ == '__main__':
    main()
