#!/usr/bin/env python3
# Issue 34 goal 2 (docs/PERFORMANCE.md, "The viewer"): a session at rest on the Cornell box: time until the refined mean's RMSE against a
# converged reference (compare.spp 4096) reaches the RMSE of reference-256 against the same truth.
# Usage: bench/viewer_refine_goal.py http://127.0.0.1:8080 SIZE TRUTH_SPP   (radiantd with --session-idle-s 600)
import json, sys, time, urllib.request
base = sys.argv[1]; size = int(sys.argv[2]); truth_spp = int(sys.argv[3])
def call(method, path, body=None):
    req = urllib.request.Request(base + path, method=method, data=None if body is None else json.dumps(body).encode(),
                                 headers={'Content-Type': 'application/json'})
    with urllib.request.urlopen(req, timeout=1200) as r: return json.loads(r.read())
cmp = {'against': 'reference', 'spp': truth_spp}
t0 = time.time()
ref = call('POST', '/v1/renders', {'scene': {'builtin': 'cornell_box'}, 'width': size, 'height': size,
           'passes': {'reference': {'spp': 256}}, 'compare': dict(cmp, aov='beauty')})
print('reference-256 vs truth: rmse', ref['stats']['metrics']['rmse'], 'render_ms', ref['stats']['render_ms'], 'wall', round(time.time()-t0,1), flush=True)
target = ref['stats']['metrics']['rmse']
dflt = call('POST', '/v1/renders', {'scene': {'builtin': 'cornell_box'}, 'width': size, 'height': size, 'compare': cmp})
print('default frame vs truth: rmse', dflt['stats']['metrics']['rmse'], 'render_ms', dflt['stats']['render_ms'], flush=True)
s = call('POST', '/v1/sessions', {'scene': {'builtin': 'cornell_box'}, 'width': size, 'height': size, 'compare': cmp,
          'refine': {'max_batches': 64, 'until_ms': 20000}})
req = urllib.request.Request(base + '/v1/sessions/' + s['id'] + '/events')
reached = None
with urllib.request.urlopen(req, timeout=120) as r:
    ev = None
    for raw in r:
        line = raw.decode().rstrip('\n')
        if line.startswith('event: '): ev = line[7:]
        elif line.startswith('data: '):
            d = json.loads(line[6:])
            if ev == 'frame':
                rmse = d.get('metrics', {}).get('rmse')
                print('batch', d['batches'], 'elapsed_ms', round(d['elapsed_ms']), 'rmse', rmse, flush=True)
                if reached is None and rmse is not None and rmse <= target: reached = d['elapsed_ms']
            if ev in ('done', 'error', 'ended'): print(ev, d); break
print('target', target, 'reached at ms', reached)
call('DELETE', '/v1/sessions/' + s['id'])
