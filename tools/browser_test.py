#!/usr/bin/env python3
"""Browser test of `cirrus preview`, driven over the DevTools protocol.

Run through tools/browser_test.sh, which installs what this needs. It:

1. starts the preview server on a copy of data/cloud.vdb (port 0) and a
   headless Chromium on the page;
2. waits until the page shows 16 spp, screenshots the canvas, and
   compares it with `cirrus render` of the page's "Copy command" (two
   seeds): the mean over the cloud within 3 % and a per-pixel z-test;
3. moves the sun-elevation slider: the spp counter must restart and the
   image must change;
4. clicks Save: exactly the two fixed files appear next to the input.

With --docs PATH it instead takes the README screenshot of the page.
"""

import argparse
import base64
import io
import json
import os
import shlex
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import urllib.request
from pathlib import Path

import numpy as np
import websocket
from PIL import Image

ROOT = Path(__file__).resolve().parent.parent


class DevTools:
    """A minimal DevTools protocol client over one page's WebSocket."""

    def __init__(self, ws_url):
        self.ws = websocket.create_connection(ws_url, timeout=60, suppress_origin=True)
        self.next_id = 0

    def call(self, method, **params):
        self.next_id += 1
        self.ws.send(json.dumps({"id": self.next_id, "method": method, "params": params}))
        while True:
            msg = json.loads(self.ws.recv())
            if msg.get("id") == self.next_id:
                if "error" in msg:
                    raise RuntimeError(f"{method}: {msg['error']}")
                return msg["result"]

    def eval(self, expr):
        r = self.call("Runtime.evaluate", expression=expr, returnByValue=True, awaitPromise=True)
        if "exceptionDetails" in r:
            raise RuntimeError(f"{expr}: {r['exceptionDetails']}")
        return r["result"].get("value")

    def wait(self, expr, timeout=120, what=None):
        deadline = time.time() + timeout
        while time.time() < deadline:
            try:
                v = self.eval(expr)
            except RuntimeError:
                v = None    # the page is still loading
            if v:
                return v
            time.sleep(0.05)
        raise TimeoutError(f"timed out waiting for {what or expr}; status {self.eval('JSON.stringify(cirrus.status)')}")

    def screenshot(self, selector=None):
        params = {"format": "png"}
        if selector:
            r = self.eval(f"JSON.stringify(document.querySelector('{selector}').getBoundingClientRect())")
            r = json.loads(r)
            params["clip"] = {"x": r["x"], "y": r["y"], "width": r["width"], "height": r["height"], "scale": 1}
        data = self.call("Page.captureScreenshot", **params)["data"]
        return Image.open(io.BytesIO(base64.b64decode(data))).convert("RGB")


def start_preview(preview_cmd, work, res, max_spp):
    # Run in the work directory on a relative name, as a user would.
    cmd = preview_cmd + ["cloud.vdb", "--port", "0", "--res", res, "--max-spp", str(max_spp)]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, text=True, cwd=work)
    line = proc.stdout.readline()
    if "http://" not in line:
        proc.kill()
        raise RuntimeError(f"{cmd}: no URL printed (got {line!r})")
    return proc, line[line.index("http://"):].split()[0]


def stop_chromium(proc):
    """Ends chromium and every process it started (its own session): the
    renderer and helper processes outlive the browser process by a moment
    and write to the profile, which the temporary directory's clean-up
    would otherwise race."""
    for sig, grace in ((signal.SIGTERM, 10), (signal.SIGKILL, 5)):
        try:
            os.killpg(proc.pid, sig)
        except ProcessLookupError:
            return
        deadline = time.time() + grace
        while time.time() < deadline:
            try:
                os.killpg(proc.pid, 0)
            except ProcessLookupError:
                proc.wait()
                return
            proc.poll()
            time.sleep(0.05)
    proc.wait()


def start_chromium(profile, width, height):
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    if not chromium:
        raise RuntimeError("chromium not found (apt-get install -y chromium)")
    proc = subprocess.Popen(
        [chromium, "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync",
         f"--user-data-dir={profile}", "--remote-debugging-port=0", f"--window-size={width},{height}",
         "--force-color-profile=srgb", "about:blank"],
        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    port_file = Path(profile) / "DevToolsActivePort"
    for _ in range(300):
        if port_file.exists() and port_file.read_text().strip():
            break
        time.sleep(0.1)
    else:
        stop_chromium(proc)
        raise RuntimeError("chromium did not open its DevTools port")
    port = port_file.read_text().split()[0]
    targets = json.load(urllib.request.urlopen(f"http://127.0.0.1:{port}/json/list"))
    page = next(t for t in targets if t["type"] == "page")
    dt = DevTools(page["webSocketDebuggerUrl"])
    dt.call("Emulation.setDeviceMetricsOverride", width=width, height=height, deviceScaleFactor=1, mobile=False)
    return proc, dt


def state(url):
    return json.load(urllib.request.urlopen(url + "state"))


def render_reference(cirrus, command, out_dir, seed, random_sampler):
    """Runs the page's command with another seed and outputs in out_dir."""
    args = shlex.split(command)
    assert args[:2] == ["cirrus", "render"], command
    args[0] = cirrus
    args[2] = str(out_dir / args[2])    # the input, relative to the server's directory
    i = args.index("-o")
    args[i + 1] = str(out_dir / f"ref{seed}.exr")
    j = args.index("--png")
    args[j + 1] = str(out_dir / f"ref{seed}.png")
    k = args.index("--seed")
    args[k + 1] = str(seed)
    if random_sampler:
        # Independent samples: their noise bounds the preview's, whose
        # passes each start a new scrambled sequence.
        args += ["--sampler", "random"]
    subprocess.run(args, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    return np.asarray(Image.open(out_dir / f"ref{seed}.png").convert("RGB"), dtype=np.float64)


def box_mean(a, r):
    """Mean over a (2r+1)^2 window, edges clamped."""
    p = np.pad(a, r, mode="edge")
    c = p.cumsum(0).cumsum(1)
    c = np.pad(c, ((1, 0), (1, 0)))
    n = 2 * r + 1
    s = c[n:, n:] - c[:-n, n:] - c[n:, :-n] + c[:-n, :-n]
    return s / (n * n)


def compare(shot, r1, r2, label):
    """Mean over the cloud and a per-pixel, per-channel z-test of `shot`
    against the mean of two independent references, whose difference
    gives the per-pixel noise. Returns (relative mean difference,
    fraction |z| > 4, mean z)."""
    ref = 0.5 * (r1 + r2)
    border = np.concatenate([ref[0], ref[-1], ref[:, 0], ref[:, -1]])
    sky = np.median(border, axis=0)
    cloud = np.abs(ref - sky).max(axis=2) > 6
    # One render's variance, from two: var(r1 - r2) = 2 var; smoothed
    # over 5x5 pixels, since one difference is a poor estimate.
    var = np.stack([box_mean((r1[..., c] - r2[..., c]) ** 2, 2) for c in range(3)], axis=2) / 2
    sigma = np.sqrt(var * 1.5 + 0.5 ** 2)      # shot + mean of two, plus 8-bit rounding
    z = ((shot - ref) / sigma)[cloud]
    rel = abs(shot[cloud].mean() - ref[cloud].mean()) / ref[cloud].mean()
    far = float((np.abs(z) > 4).mean())
    print(f"{label}: cloud {cloud.mean() * 100:.0f}% of pixels, mean diff {rel * 100:.2f}%, "
          f"|z|>4 {far * 100:.2f}%, mean z {z.mean():+.3f}")
    return rel, far, float(z.mean())


def test(args, work):
    proc, url = start_preview(args.preview, work, "160x120", 16)
    browser = None
    try:
        browser, dt = start_chromium(work / "profile", 1000, 640)
        dt.call("Page.navigate", url=url)
        done = "cirrus.status && cirrus.status.type === 'frame' && !cirrus.status.preview && cirrus.status.spp >= 16"
        t0 = time.time()
        dt.wait(done, what="16 spp")
        print(f"16 spp after {time.time() - t0:.1f} s")
        assert dt.eval("document.getElementById('spp').textContent") == "16"
        shot = dt.screenshot("#view")
        assert shot.size == (160, 120), shot.size
        shot.save(work / "shot.png")
        dt.eval("document.getElementById('copy').click()")
        command = dt.wait("document.getElementById('command').value", what="the command")
        print(command)
        assert "--spp 16" in command, command

        help_text = subprocess.run([args.cirrus, "render", "--help"], capture_output=True, text=True).stdout
        random_sampler = "--sampler" in help_text
        refs = [render_reference(args.cirrus, command, work, s, random_sampler) for s in (1001, 2002, 3003)]
        a = np.asarray(shot, dtype=np.float64)
        control = compare(refs[2], refs[0], refs[1], "control: a third CLI render")
        got = compare(a, refs[0], refs[1], "preview")
        assert got[0] < 0.03, f"cloud mean differs by {got[0] * 100:.2f}%"
        assert got[1] < max(0.01, 2 * control[1]), f"{got[1] * 100:.2f}% of cloud pixels have |z| > 4"
        assert abs(got[2]) < 0.3, f"mean z {got[2]:+.3f}"

        # Move the sun: accumulation restarts and the image changes.
        v0 = state(url)["version"]
        n0 = dt.eval("cirrus.history.length")
        dt.eval("""(() => { const e = document.getElementById('elevation');
                    e.value = 75; e.dispatchEvent(new Event('input'));
                    e.dispatchEvent(new Event('change')); })()""")
        dt.wait(f"fetch('/state').then(r => r.json()).then(s => s.version > {v0})", what="the change")
        v1 = state(url)["version"]
        dt.wait(f"cirrus.status.version >= {v1} && !cirrus.status.preview && cirrus.status.spp >= 16",
                what="16 spp again")
        after = dt.eval(f"cirrus.history.slice({n0})")
        restarted = [h for h in after if h["version"] > v0 and h["spp"] < 16]
        assert restarted, f"the spp counter did not restart: {after}"
        print(f"after the slider: spp {[h['spp'] for h in after if h['version'] > v0][:8]} ...")
        moved = np.asarray(dt.screenshot("#view"), dtype=np.float64)
        change = np.abs(moved - a).mean()
        print(f"mean change of the image: {change:.1f} levels")
        assert change > 2.0, "the image did not change"

        # Orbit with the mouse and zoom with the wheel: the camera moves.
        cam0 = state(url)["view"]["camera"]
        r = json.loads(dt.eval("JSON.stringify(document.getElementById('view').getBoundingClientRect())"))
        cx, cy = r["x"] + r["width"] / 2, r["y"] + r["height"] / 2
        dt.call("Input.dispatchMouseEvent", type="mousePressed", x=cx, y=cy, button="left", clickCount=1)
        for i in range(1, 6):
            dt.call("Input.dispatchMouseEvent", type="mouseMoved", x=cx + 8 * i, y=cy + 2 * i, button="left")
        dt.call("Input.dispatchMouseEvent", type="mouseReleased", x=cx + 40, y=cy + 10, button="left", clickCount=1)
        dt.call("Input.dispatchMouseEvent", type="mouseWheel", x=cx, y=cy, deltaX=0, deltaY=200)
        dt.wait("!cirrus.status.preview && cirrus.status.integrator === 'path'", what="path tracing after the drag")
        time.sleep(0.5)
        cam1 = state(url)["view"]["camera"]
        dist = lambda c: sum((a - b) ** 2 for a, b in zip(c["from"], c["to"])) ** 0.5
        assert cam1["to"] == cam0["to"], "orbit and zoom keep the target"
        assert cam1["from"] != cam0["from"], "the drag did not orbit"
        assert dist(cam1) > dist(cam0) * 1.1, f"the wheel did not zoom out: {dist(cam0)} -> {dist(cam1)}"
        assert not state(url)["view"]["interactive"], "still interactive after the drag"
        print(f"orbit and zoom: camera distance {dist(cam0):.0f} -> {dist(cam1):.0f}")

        dt.eval("document.getElementById('save').click()")
        dt.wait("document.getElementById('message').textContent.startsWith('wrote')", what="save")
        names = sorted(p.name for p in work.iterdir() if p.name.startswith("cloud."))
        assert names == ["cloud.preview.exr", "cloud.preview.png", "cloud.vdb"], names
        print("browser test passed")
    finally:
        proc.terminate()
        if browser:
            stop_chromium(browser)
        proc.wait()


def docs(args, work):
    """The README screenshot: the whole page, palette-quantised."""
    proc, url = start_preview(args.preview, work, "480x360", 64)
    browser = None
    try:
        browser, dt = start_chromium(work / "profile", 820, 560)
        dt.call("Page.navigate", url=url)
        dt.wait("cirrus.status && !cirrus.status.preview && cirrus.status.spp >= 64", timeout=600)
        img = dt.screenshot()
        img.save(args.docs, optimize=True)
        if os.path.getsize(args.docs) > 190_000:
            img.quantize(colors=256, method=Image.Quantize.MEDIANCUT).save(args.docs, optimize=True)
        print(f"{args.docs}: {img.size[0]}x{img.size[1]}, {os.path.getsize(args.docs) // 1024} KiB")
    finally:
        proc.terminate()
        if browser:
            stop_chromium(browser)
        proc.wait()


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cirrus", required=True, help="the cirrus binary (for `cirrus render`)")
    ap.add_argument("--preview", required=True, help="the preview command, e.g. 'cirrus preview'")
    ap.add_argument("--docs", help="write the README screenshot here instead of testing")
    args = ap.parse_args()
    args.preview = shlex.split(args.preview)
    with tempfile.TemporaryDirectory(prefix="cirrus-browser-") as tmp:
        work = Path(tmp)
        shutil.copy(ROOT / "data" / "cloud.vdb", work / "cloud.vdb")
        (docs if args.docs else test)(args, work)


if __name__ == "__main__":
    sys.exit(main())
