#!/usr/bin/python3
"""report.browser: `iris report` over a real bench output (and a validate
output when `iris validate` exists), served on localhost and opened in
headless Chromium through the DevTools protocol.

Checks: every <img> (renders, difference images, charts) loaded with
naturalWidth > 0; the console has no errors or exceptions; no request failed
or left localhost/data: URIs; the page has no scripts and no external URLs.
A control page with a missing image, a console.error and an exception must
be caught by the same checks (so this test can fail).
Skipped (77) only when /usr/bin/chromium is absent.

Usage: test_report.py WORKDIR IRIS PLOT_SCRIPT
"""
import functools
import http.server
import os
import re
import shutil
import subprocess
import sys
import threading

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import cdp  # noqa: E402
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
import checks  # noqa: E402
from checks import check  # noqa: E402

CHROMIUM = os.environ.get("IRIS_CHROMIUM", "/usr/bin/chromium")


def run(cmd, cwd):
    p = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, timeout=240)
    return p.returncode, p.stdout, p.stderr


class Server:
    """The report folder on http://127.0.0.1:<free port>/, requests recorded."""

    def __init__(self, root):
        self.paths = []
        paths = self.paths

        class Handler(http.server.SimpleHTTPRequestHandler):
            def log_message(self, fmt, *args):
                paths.append(self.path)

        self.httpd = http.server.ThreadingHTTPServer(
            ("127.0.0.1", 0), functools.partial(Handler, directory=root))
        self.port = self.httpd.server_address[1]
        self.thread = threading.Thread(target=self.httpd.serve_forever, daemon=True)
        self.thread.start()

    def close(self):
        self.httpd.shutdown()
        self.httpd.server_close()


IMAGES_JS = """(async () => {
  const imgs = Array.from(document.images);
  await Promise.all(imgs.map(i => i.decode().catch(() => null)));
  return imgs.map(i => ({src: i.currentSrc.slice(0, 48), alt: i.alt,
                         complete: i.complete, w: i.naturalWidth, h: i.naturalHeight}));
})()"""


def inspect(browser, url, port):
    """Loads url; returns (images, console errors, bad requests)."""
    browser.events.clear()
    for domain in ("Page", "Runtime", "Log", "Network"):
        browser.call(domain + ".enable")
    browser.call("Page.navigate", {"url": url})
    browser.wait_event("Page.loadEventFired", timeout=90)
    browser.drain(1.0)
    images = browser.evaluate(IMAGES_JS)
    browser.drain(0.3)
    errors, bad = [], []
    for e in browser.events:
        m, p = e["method"], e.get("params", {})
        if m == "Runtime.consoleAPICalled" and p.get("type") in ("error", "assert"):
            errors.append("console." + p["type"] + ": " +
                          " ".join(str(a.get("value", a.get("description", ""))) for a in p.get("args", [])))
        elif m == "Runtime.exceptionThrown":
            d = p.get("exceptionDetails", {})
            errors.append("exception: " + d.get("text", "") + " " +
                          str(d.get("exception", {}).get("description", "")))
        elif m == "Log.entryAdded" and p.get("entry", {}).get("level") == "error":
            errors.append("log: " + p["entry"].get("text", ""))
        elif m == "Network.loadingFailed":
            bad.append("failed: " + p.get("errorText", ""))
        elif m == "Network.requestWillBeSent":
            u = p.get("request", {}).get("url", "")
            if not (u.startswith(f"http://127.0.0.1:{port}/") or u.startswith("data:")):
                bad.append("left localhost: " + u)
        elif m == "Network.responseReceived":
            st = p.get("response", {}).get("status", 200)
            if st >= 400:
                bad.append(f"HTTP {st}: {p['response'].get('url', '')}")
    return images, errors, bad


def main(argv):
    work, iris, plot = argv[1], argv[2], argv[3]
    if not os.access(CHROMIUM, os.X_OK):
        print(f"SKIP: {CHROMIUM} is not installed (tools/setup.sh --tests installs it)")
        return 77
    shutil.rmtree(work, ignore_errors=True)
    site = os.path.join(work, "site")
    os.makedirs(site)

    # real outputs: a tiny bench, and a validation of the stored Cornell reference
    rc, so, se = run([iris, "bench", "cornell-box", "--methods", "mis,nee", "--times", "0.2,0.5",
                      "--height", "32", "--reference", "auto", "--reference-spp", "256",
                      "--cache", os.path.join(work, "cache"), "--plot-script", plot,
                      "--out", os.path.join(site, "bench"), "--quiet"], work)
    if not check(rc == 0, f"iris bench: exit {rc}: {se}"):
        return 1
    have_validate = run([iris, "validate", "--help"], work)[0] == 0
    if have_validate:
        rc, so, se = run([iris, "validate", "cornell-box", "--spp", "4", "--method", "mis",
                          "--out", os.path.join(site, "validate"), "--quiet"], work)
        # validate's own tests judge validate; here it only has to provide a page section
        have_validate = os.path.exists(os.path.join(site, "validate", "summary.json"))
        if not have_validate:
            print(f"note: iris validate wrote no summary.json (exit {rc}: {se.strip()}); "
                  "checking the bench section only")
    rc, so, se = run([iris, "report", site], work)
    if not check(rc == 0, f"iris report: exit {rc}: {se}"):
        return 1
    page = os.path.join(site, "index.html")
    html = open(page, encoding="utf-8").read()

    # static checks: self-contained
    check("<script" not in html.lower(), "no scripts in the page")
    ext = re.findall(r'(?:src|href)\s*=\s*"(https?:|//)[^"]*', html)
    check(not ext, f"no external URLs: {ext[:3]}")
    n_img = len(re.findall(r"<img\b", html))
    # bench: 1 chart + reference + 2 methods x (image + diff); validate: cycles + 3 per method
    expect = 1 + 1 + 4 + (4 if have_validate else 0)
    check(n_img == expect, f"{n_img} <img> in the page, expected {expect}")
    check("time to relMSE" in html and ">nee<" in html, "the bench table is embedded")
    check(not have_validate or "Validation: cornell-box" in html, "the validate section")

    # a control page that must fail every check
    with open(os.path.join(site, "control.html"), "w") as f:
        f.write('<!DOCTYPE html><html><head><meta charset="utf-8"><link rel="icon" href="data:,">'
                '<title>control</title></head><body><img src="missing.png" alt="missing">'
                '<script>console.error("control error"); throw new Error("control exception");'
                '</script></body></html>')

    server = Server(site)
    browser = None
    try:
        browser = cdp.Browser(CHROMIUM)
        base = f"http://127.0.0.1:{server.port}/"
        images, errors, bad = inspect(browser, base + "index.html", server.port)
        check(len(images) == n_img, f"browser sees {len(images)} images, the HTML has {n_img}")
        for im in images:
            check(im["complete"] and im["w"] > 0 and im["h"] > 0, f"image did not load: {im}")
        check(not errors, f"console errors: {errors}")
        check(not bad, f"bad requests: {bad}")
        check(server.paths and all(p.split("?")[0] in ("/index.html",) for p in server.paths),
              f"only the page itself is fetched (images are embedded): {server.paths}")
        print(f"report.browser: {len(images)} images loaded, {len(errors)} console errors")

        # the control page: the same checks must see each fault
        c_images, c_errors, c_bad = inspect(browser, base + "control.html", server.port)
        check(any(im["w"] == 0 for im in c_images), f"control: broken image not detected: {c_images}")
        check(any("control error" in e for e in c_errors), f"control: console.error missed: {c_errors}")
        check(any("control exception" in e for e in c_errors), f"control: exception missed: {c_errors}")
        check(any("404" in b for b in c_bad), f"control: 404 missed: {c_bad}")
    finally:
        if browser:
            browser.close()
        server.close()
    if not checks.failures:
        shutil.rmtree(work, ignore_errors=True)
    return checks.summary("report.browser")


if __name__ == "__main__":
    sys.exit(main(sys.argv))
