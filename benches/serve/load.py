#!/usr/bin/env python3
"""Load on `phong serve`: N clients at once, each rendering frames back to back (the newest-wins
page keeps one frame in flight per client), for a fixed time. Prints errors, frames per client,
latency percentiles, and the server's peak memory (VmHWM) when given its pid.

  phong serve --port 8099 --threads 2 &
  python3 benches/serve/load.py --url http://127.0.0.1:8099 --clients 20 --seconds 20 --pid $!
"""
import argparse, json, threading, time, urllib.request, urllib.error

ap = argparse.ArgumentParser()
ap.add_argument("--url", default="http://127.0.0.1:8099")
ap.add_argument("--clients", type=int, default=20)
ap.add_argument("--seconds", type=float, default=20)
ap.add_argument("--width", type=int, default=1280)
ap.add_argument("--height", type=int, default=720)
ap.add_argument("--format", default="rgba", choices=["rgba", "png"])
ap.add_argument("--pid", type=int)
a = ap.parse_args()

scene = json.load(urllib.request.urlopen(a.url + "/api/scene"))["scene"]
scene["image"].update(width=a.width, height=a.height, antialias=1)
body = json.dumps(scene).encode()
stop = time.monotonic() + a.seconds
results = [dict(ok=0, errors={}, ms=[]) for _ in range(a.clients)]
peak = [0]


def client(i):
    r = results[i]
    while time.monotonic() < stop:
        t = time.perf_counter()
        req = urllib.request.Request(f"{a.url}/api/render?format={a.format}", data=body,
                                     headers={"Content-Type": "application/json", "X-Phong-Client": f"load-{i}"})
        try:
            with urllib.request.urlopen(req, timeout=60) as resp:
                resp.read()
            r["ok"] += 1
            r["ms"].append((time.perf_counter() - t) * 1e3)
        except urllib.error.HTTPError as e:
            r["errors"][e.code] = r["errors"].get(e.code, 0) + 1
        except Exception as e:  # noqa: BLE001
            r["errors"][type(e).__name__] = r["errors"].get(type(e).__name__, 0) + 1


def memory():
    while time.monotonic() < stop and a.pid:
        with open(f"/proc/{a.pid}/status") as f:
            for line in f:
                if line.startswith("VmRSS:"):
                    peak[0] = max(peak[0], int(line.split()[1]))
        time.sleep(0.2)


threads = [threading.Thread(target=client, args=(i,)) for i in range(a.clients)] + [threading.Thread(target=memory)]
for t in threads:
    t.start()
for t in threads:
    t.join()
ms = sorted(m for r in results for m in r["ms"])
frames = [r["ok"] for r in results]
errors = {}
for r in results:
    for k, v in r["errors"].items():
        errors[k] = errors.get(k, 0) + v
q = lambda p: ms[min(len(ms) - 1, int(p * (len(ms) - 1)))] if ms else float("nan")
print(f"clients={a.clients} seconds={a.seconds} {a.width}x{a.height} format={a.format}: frames={len(ms)} "
      f"({len(ms) / a.seconds:.1f}/s) per client min={min(frames)} max={max(frames)} errors={errors or 0} "
      f"latency median={q(0.5):.0f}ms p95={q(0.95):.0f}ms max={q(1.0):.0f}ms"
      + (f" server peak RSS={peak[0] / 1024:.0f} MB" if a.pid else ""))
