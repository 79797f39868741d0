#!/usr/bin/env python3
"""End-to-end test of vitri studio in a real browser (headless Chromium driven by Selenium).

Starts `vitri studio` on a free port, opens the page, adds a constraint by clicking on the surface, drags
it, undoes both edits, and checks through the HTTP API that the mesh changed, stayed closed (every edge
shared by exactly two triangles) and came back. Screenshots go to --out (kept as test artifacts).

Usage: studio_browser.py --vitri PATH/TO/vitri --out DIR [--model FILE] [--bench | --api-bench]
                         [--precision P] [--studio-args "..."] [--window W,H] [--query "aa=1&lowres=0"]
Exit status: 0 pass, 1 fail, 77 skipped (no browser, driver or selenium installed).
--bench measures the edit-to-screen latency and drag rate in the page and prints them (docs/benchmarks.md).
"""
import argparse
import json
import math
import os
import shutil
import struct
import sys
import tempfile
import time
import urllib.request

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from studio_server import Failure, Server, wait_for  # noqa: E402

SKIP = 77


def skip(why):
    print("SKIP: " + why + " (Debian: apt-get install chromium chromium-driver python3-selenium)")
    sys.exit(SKIP)


try:
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.actions.action_builder import ActionBuilder
    from selenium.webdriver.common.keys import Keys
except ImportError:
    skip("python3-selenium is not installed")


def check(cond, what):
    if not cond:
        raise Failure(what)
    print("ok: " + what)


def edges_closed(mesh):
    """True when every undirected edge is used by exactly two triangles, in opposite directions."""
    count = {}
    for a, b, c in mesh["triangles"]:
        for u, v in ((a, b), (b, c), (c, a)):
            count[(u, v)] = count.get((u, v), 0) + 1
    for (u, v), n in count.items():
        if n != 1 or count.get((v, u), 0) != 1:
            return False
    return len(mesh["triangles"]) > 0


def max_vertex_distance(a, b):
    """Largest distance from a vertex of mesh a to the nearest vertex of mesh b (uniform grid)."""
    vb = b["vertices"]
    lo = [min(p[k] for p in vb) for k in range(3)]
    hi = [max(p[k] for p in vb) for k in range(3)]
    cell = max(hi[k] - lo[k] for k in range(3)) / 40 or 1.0
    grid = {}
    for p in vb:
        grid.setdefault(tuple(int((p[k] - lo[k]) // cell) for k in range(3)), []).append(p)
    worst = 0.0
    for p in a["vertices"]:
        c = [int((p[k] - lo[k]) // cell) for k in range(3)]
        best, r = math.inf, 0
        while best == math.inf or (r - 1) * cell < best:
            for i in range(c[0] - r, c[0] + r + 1):
                for j in range(c[1] - r, c[1] + r + 1):
                    for k in range(c[2] - r, c[2] + r + 1):
                        if max(abs(i - c[0]), abs(j - c[1]), abs(k - c[2])) != r:
                            continue
                        for q in grid.get((i, j, k), ()):
                            best = min(best, math.dist(p, q))
            r += 1
            if r > 200:
                break
        worst = max(worst, best)
    return worst


def launch_browser(out_dir, window="1280,800"):
    chromium = shutil.which("chromium") or shutil.which("chromium-browser") or shutil.which("google-chrome")
    driver_path = shutil.which("chromedriver") or "/usr/bin/chromedriver"
    if not chromium:
        skip("no chromium binary")
    if not os.path.exists(driver_path):
        skip("no chromedriver")
    opts = webdriver.ChromeOptions()
    opts.binary_location = chromium
    profile = tempfile.mkdtemp(prefix="vitri-studio-chromium-", dir=out_dir)
    for flag in ["--headless=new", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
                 "--disable-component-update", "--disable-sync", "--no-first-run", "--disable-dev-shm-usage",
                 "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--window-size=" + window,
                 "--user-data-dir=" + profile]:
        opts.add_argument(flag)
    opts.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    driver = webdriver.Chrome(service=Service(driver_path), options=opts)
    driver.set_script_timeout(600)
    return driver, profile


def page_idle(driver):
    """The page's edit queue is empty (no request in flight) and no drag is going on."""
    return driver.execute_async_script(
        "const done = arguments[arguments.length - 1];"
        "window.studio.busy.then(() => done(window.studio.drag === null));")


def pointer_to(driver, x, y):
    ab = ActionBuilder(driver)
    ab.pointer_action.move_to_location(int(round(x)), int(round(y)))
    ab.perform()


def api_bench(server):
    """Edit + delta round trips from a script (no browser): the server's and the transfer's share."""
    def post(path, body):
        req = urllib.request.Request(server.url + path, data=json.dumps(body).encode(), method="POST")
        with urllib.request.urlopen(req, timeout=600) as r:
            return json.loads(r.read())

    def pull(version, exact):
        with urllib.request.urlopen("%s/api/mesh?since=%d&exact=%d" % (server.url, version, exact)) as r:
            data = r.read()
        return int.from_bytes(data[8:12], "little")

    def median(v):
        v = sorted(v)
        return {"median": v[len(v) // 2], "p90": v[min(len(v) - 1, int(0.9 * len(v)))]}

    post("/api/refine", {"all": True})
    state = server.get("/api/state")
    unit, version = state["unit"], pull(0, 1)
    index = next(c["index"] for c in state["constraint_list"] if c["value"] == 0)
    c = state["constraint_list"][index]["position"]
    drag, server_ms = [], []
    for k in range(1, 61):
        a = 2 * math.pi * k / 60
        t0 = time.perf_counter()
        s = post("/api/edit", {"op": "move", "index": index, "merge": k > 1,
                               "position": [c[0] + 0.01 * unit * math.sin(a), c[1] + 0.01 * unit * (1 - math.cos(a)), c[2]]})
        version = pull(version, 0)
        drag.append(1e3 * (time.perf_counter() - t0))
        server_ms.append(s["edit_ms"] + s["extract_ms"])
    post("/api/undo", {})
    post("/api/refine", {"all": True})  # back to the target after the drag's level (docs/studio.md)
    version = pull(version, 1)
    add, follow, previews = [], [], 0
    for k in range(12):
        t0 = time.perf_counter()
        s = post("/api/edit", {"op": "add", "value": 0, "position": [c[0] + 0.004 * unit * (k - 5.5), c[1], c[2]]})
        version = pull(version, 1)
        add.append(1e3 * (time.perf_counter() - t0))
        previews += s["preview"]
        t0 = time.perf_counter()
        while not post("/api/refine", {})["refined"]:  # the target mesh again (after a preview)
            pass
        version = pull(version, 1)
        follow.append(1e3 * (time.perf_counter() - t0))
        post("/api/undo", {})
        post("/api/refine", {"all": True})
        version = pull(version, 1)
    print("API_BENCH " + json.dumps({"model": state["name"], "load_average": os.getloadavg()[0],
                                     "triangles": state["triangles"], "drag": median(drag),
                                     "drag_server_edit_extract": median(server_ms),
                                     "drag_updates_per_second": 1e3 * len(drag) / sum(drag), "add": median(add),
                                     "adds_on_preview": previews, "target_after_add": median(follow)}))
    return 0


def click_drag_undo(driver, server, shot, s0, m0):
    """Adds a constraint by clicking the surface, drags it, undoes both; checks the mesh each time."""
    # 1. Click on the surface (middle of the view: the model is framed there): on-surface constraint.
    canvas = driver.find_element("css selector", "#view canvas")
    ActionChains(driver).move_to_element(canvas).click().perform()
    wait_for("the new constraint", lambda: server.get("/api/stats")["constraints"] == s0["constraints"] + 1)
    wait_for("the page to be idle", lambda: page_idle(driver))
    shot("studio-1-added.png")
    s1 = server.get("/api/state")
    added = s1["constraint_list"][-1]
    check(added["value"] == 0, "the click added an on-surface constraint (value 0)")
    m1 = server.get("/api/mesh?format=indexed")
    check(m1 != m0, "the mesh changed after the click")
    check(edges_closed(m1), "the mesh is closed after the click")

    # 2. Drag the new constraint across the screen in small steps.
    p = driver.execute_script("return studio.screenOf(arguments[0])", added["index"])
    pointer_to(driver, p["x"], p["y"])
    ActionChains(driver).click_and_hold().perform()
    for k in range(1, 11):
        pointer_to(driver, p["x"] + 6 * k, p["y"] - 4 * k)
        time.sleep(0.03)
    ActionChains(driver).release().perform()
    wait_for("the drag to end", lambda: page_idle(driver))
    shot("studio-2-dragged.png")
    s2 = server.get("/api/state")
    moved = s2["constraint_list"][added["index"]]
    check(moved["position"] != added["position"], "the drag moved the constraint")
    check(s2["undo"] == s1["undo"] + 1, "the drag is one undo step")
    m2 = server.get("/api/mesh?format=indexed")
    check(m2 != m1, "the mesh followed the drag")
    check(edges_closed(m2), "the mesh is closed after the drag")

    # 3. Undo the drag (Ctrl+Z) and the click (the Undo button).
    ActionChains(driver).key_down(Keys.CONTROL).send_keys("z").key_up(Keys.CONTROL).perform()
    wait_for("undo of the drag", lambda: server.get("/api/stats")["undo"] == s1["undo"])
    driver.find_element("id", "undo").click()
    wait_for("undo of the click", lambda: server.get("/api/stats")["constraints"] == s0["constraints"])
    wait_for("the page to be idle", lambda: page_idle(driver))
    shot("studio-3-undone.png")
    s3 = server.get("/api/state")
    check(s3["constraint_list"] == s0["constraint_list"], "the constraints came back exactly")
    m3 = server.get("/api/mesh?format=indexed")
    check(edges_closed(m3), "the mesh is closed after the undos")
    tol = 2 * s0["precision"] * s0["unit"]
    d = max(max_vertex_distance(m3, m0), max_vertex_distance(m0, m3))
    check(d <= tol, "the mesh came back (vertex distance %.3g <= %.3g, %d vs %d triangles)"
          % (d, tol, len(m3["triangles"]), len(m0["triangles"])))
    check(driver.execute_script("return studio.slots.triangles") == len(m3["triangles"]),
          "the page draws the server's triangle count after the deltas")
    check(page_mesh_matches(driver, server), "the page's triangles are the server's, corner for corner (float32)")
    check(page_constraints_match(driver, server), "the page's constraint list is the server's after the edits")
    check(full_constraint_fetches(driver) == 1,
          "the page took the constraint list once (at load), then only the changes of each edit")
    check(requests_sent(driver, "socket", "/api/edit") >= 2 and requests_sent(driver, "http", "/api/edit") == 0,
          "the page sent its edits over the WebSocket (%d), none over HTTP"
          % requests_sent(driver, "socket", "/api/edit"))


def open_file(driver, server, shot, out_dir):
    """Opens a .xyzv file through the page's file input."""
    # 4. Open a file through the page (uploaded as the request body, parsed from memory).
    upload = os.path.abspath(os.path.join(out_dir, "studio-upload.xyzv"))
    with open(upload, "w") as f:
        f.write("0 0 0 -1\n")
        for i in range(12):
            a = 2 * math.pi * i / 12
            f.write("%r %r %r 0\n" % (math.cos(a), math.sin(a), 0.5 * (-1) ** i))
        f.write("0 0 1.2 0\n0 0 -1.2 0\n")
    driver.find_element("id", "open").send_keys(upload)
    wait_for("the upload", lambda: server.get("/api/stats")["name"] == "studio-upload.xyzv")
    wait_for("the page to be idle", lambda: page_idle(driver))
    s4 = server.get("/api/stats")
    check(s4["constraints"] == 15 and s4["undo"] == 0, "the uploaded file replaced the model")
    check(page_constraints_match(driver, server), "the page holds the uploaded model's constraints")
    check(edges_closed(server.get("/api/mesh?format=indexed")), "the uploaded model's mesh is closed")
    # Refinement goes on while the page is idle: compare the page's mesh with the server's once it ended.
    wait_for("refinement of the uploaded model", lambda: server.get("/api/stats")["refined"], 300)
    wait_for("the page to be idle", lambda: page_idle(driver))
    time.sleep(0.5)
    wait_for("the page to be idle", lambda: page_idle(driver))
    check(driver.execute_script("return studio.slots.triangles") == server.get("/api/stats")["triangles"],
          "the page draws the uploaded model")
    shot("studio-4-opened.png")
    # Shift+click: an outside constraint (value +depth); alt+click: an inside one (value -depth).
    canvas = driver.find_element("css selector", "#view canvas")
    for key, sign, what, dx, dy in ((Keys.SHIFT, 1, "outside", -70, 50), (Keys.ALT, -1, "inside", 60, -40)):
        n = server.get("/api/stats")["constraints"]
        ActionChains(driver).move_to_element_with_offset(canvas, dx, dy).key_down(key).click().key_up(key).perform()
        wait_for("the %s constraint" % what, lambda: server.get("/api/stats")["constraints"] == n + 1)
        wait_for("the page to be idle", lambda: page_idle(driver))
        value = server.get("/api/state")["constraint_list"][-1]["value"]
        check(value * sign > 0, "modifier click added an %s constraint (value %g)" % (what, value))
        check(page_constraints_match(driver, server), "the page's constraint list is the server's")
    check(edges_closed(server.get("/api/mesh?format=indexed")), "the mesh is closed after them")
    shot("studio-5-modifiers.png")
    pick_rule(driver, server)


RAYCAST = """const rect = studio.renderer.domElement.getBoundingClientRect(), unit = studio.stats.unit;
const out = { hits: 0, disagree: [] };
for (let k = 0; k < 40; ++k) {
  const ev = { clientX: rect.left + rect.width * (0.1 + 0.8 * ((k * 0.618034) % 1)),
               clientY: rect.top + rect.height * (0.1 + 0.8 * ((k * 0.41421) % 1)) };
  const three = studio.ray(ev).intersectObject(studio.slots.mesh)[0] || null;
  const ours = studio.slots.raycast(studio.ray(ev).ray);
  if (!three !== !ours || (three && (three.point.distanceTo(ours.point) > 1e-9 * unit ||
                                     three.face.normal.distanceTo(ours.face.normal) > 1e-6)))
    out.disagree.push(k);
  if (ours) ++out.hits;
}
return out;"""


def raycast_agrees(driver):
    """The page's own raycast (the slots' float32 positions) hits what three.js's Mesh.raycast hits."""
    r = driver.execute_script(RAYCAST)
    check(r["hits"] > 10 and not r["disagree"],
          "the page's raycast agrees with three.js's (%d of 40 rays hit the mesh, disagreeing: %s)"
          % (r["hits"], r["disagree"]))


PICK_RULE = """const done = arguments[arguments.length - 1];
(async () => {
  await studio.settled();
  const hit = studio.surfacePixels(1)[0];
  const p = studio.pickSurface({ clientX: hit.x, clientY: hit.y }).point, unit = studio.stats.unit;
  // q: drawn 4 pixels right of p, 0.01 x the diagonal nearer to the camera (an outside constraint in
  // front of its sample); far: drawn on p, 0.1 x the diagonal behind it (the far side of a model).
  const ndc = p.clone().project(studio.camera), rect = studio.renderer.domElement.getBoundingClientRect();
  const side = new THREE.Vector3(ndc.x + 8 / rect.width, ndc.y, ndc.z).unproject(studio.camera);
  const toCamera = studio.camera.position.clone().sub(side).normalize();
  const q = side.addScaledVector(toCamera, 0.01 * unit);
  const far = p.clone().addScaledVector(studio.camera.position.clone().sub(p).normalize(), -0.1 * unit);
  const n = studio.constraints.count;
  await studio.edit({ op: 'add', position: [p.x, p.y, p.z], value: 0 });
  await studio.edit({ op: 'add', position: [q.x, q.y, q.z], value: 0.01 * unit });
  await studio.edit({ op: 'add', position: [far.x, far.y, far.z], value: 0.1 * unit });
  await studio.settled();
  const at = (i) => { const s = studio.screenOf(i); return studio.pickConstraint({ clientX: s.x, clientY: s.y }); };
  const s = studio.screenOf(n), t = studio.screenOf(n + 1);
  const out = { count: studio.constraints.count - n, p: at(n), q: at(n + 1), far: at(n + 2), n,
                gap: Math.hypot(s.x - t.x, s.y - t.y) };
  for (let k = 0; k < 3; ++k) await studio.command('/api/undo');
  await studio.settled();
  return out;
})().then(done, (e) => done({ error: String(e) }));"""


def pick_rule(driver, server):
    """The pointer picks the constraint drawn nearest to it among those near the front: a sample beside
    an outside constraint drawn in front of it, not the far side of the model under the near one."""
    n = server.get("/api/stats")["constraints"]
    r = driver.execute_async_script(PICK_RULE)
    check("error" not in r and r["count"] == 3, "three constraints added for the pick test " + json.dumps(r))
    check(3 < r["gap"] < 8, "the outside constraint is drawn within the pick radius of its sample (%.1f px)" % r["gap"])
    check(r["p"] == r["n"], "the pointer on the sample picks it, not the outside constraint in front")
    check(r["q"] == r["n"] + 1, "the pointer on the outside constraint picks it")
    check(r["far"] in (r["n"], r["n"] + 1), "the pointer does not pick through to the far side")
    wait_for("the undos", lambda: server.get("/api/stats")["constraints"] == n)


def http_only(driver, server):
    """The page without its WebSocket: closed during a session (later requests over HTTP), then
    ?socket=0 (as when the socket cannot open): edits over HTTP."""
    wait_for("the target precision", lambda: server.get("/api/stats")["refined"], 300)
    wait_for("the page to be idle", lambda: page_idle(driver))
    driver.execute_script("api.socket.close()")
    wait_for("the socket to close", lambda: driver.execute_script("return api.socket === null"))
    before = requests_sent(driver, "http", "/api/undo")
    n = server.get("/api/stats")["undo"]
    driver.find_element("id", "undo").click()
    wait_for("the undo after the socket closed", lambda: server.get("/api/stats")["undo"] == n - 1)
    check(requests_sent(driver, "http", "/api/undo") == before + 1,
          "after the socket closed, the page's undo went over HTTP")
    driver.get(server.url + "/?socket=0")
    wait_for("the page to start", lambda: driver.execute_script("return !!(window.studio && studio.ready)"))
    wait_for("the page to be idle", lambda: page_idle(driver))
    check(driver.execute_script("return api.socket === null"), "?socket=0: the page has no socket")
    n = server.get("/api/stats")["constraints"]
    # The centroid of a mesh triangle: near the surface, and never a constraint (on-surface constraints
    # can be mesh vertices, and an add there would be a duplicate).
    m = server.get("/api/mesh?format=indexed")
    corners = [m["vertices"][i] for i in m["triangles"][0]]
    p = [sum(c[k] for c in corners) / 3 for k in range(3)]
    error = driver.execute_async_script(
        "const done = arguments[arguments.length - 1];"
        "studio.edit({op: 'add', position: arguments[0], value: 0}).then(() => done(''), (e) => done(String(e)));", p)
    check(server.get("/api/stats")["constraints"] == n + 1, "?socket=0: the page's add reached the server " + error)
    driver.find_element("id", "undo").click()
    wait_for("its undo", lambda: server.get("/api/stats")["constraints"] == n)
    check(requests_sent(driver, "http", "/api/edit") == 1 and requests_sent(driver, "socket", "/api/edit") == 0,
          "?socket=0: the edit went over HTTP")
    check(page_mesh_matches(driver, server), "?socket=0: the page's triangles are the server's after an add and its undo")


def run(args):
    server = Server(args.vitri, ([args.model] if args.model else []) + ["--precision", str(args.precision)] +
                    args.studio_args.split())
    driver = None
    profile = None
    try:
        if args.api_bench:
            return api_bench(server)
        driver, profile = launch_browser(args.out, args.window)
        query = "&".join(q for q in (["aa=0"] if args.no_antialias else []) + ([args.query] if args.query else []))
        driver.get(server.url + "/" + ("?" + query if query else ""))
        wait_for("the page to start", lambda: driver.execute_script("return !!(window.studio && studio.ready)"))
        webgl = driver.execute_script("return !!studio.renderer.getContext()")
        check(webgl, "the page has a WebGL context")
        # Progressive refinement runs while the page is idle: wait until it reached the target.
        wait_for("refinement to the target precision", lambda: server.get("/api/stats")["refined"], 300)
        wait_for("the page to be idle", lambda: page_idle(driver))
        time.sleep(0.5)
        wait_for("the page to be idle", lambda: page_idle(driver))
        shot = lambda name: driver.save_screenshot(os.path.join(args.out, name))
        shot("studio-0-loaded.png")
        s0 = server.get("/api/state")
        m0 = server.get("/api/mesh?format=indexed")
        check(edges_closed(m0), "the loaded mesh is closed (%d triangles)" % len(m0["triangles"]))
        check(driver.execute_script("return studio.slots.triangles") == len(m0["triangles"]),
              "the page draws as many triangles as the server holds")
        if args.bench:
            return bench(driver, server, args.out)

        raycast_agrees(driver)
        click_drag_undo(driver, server, shot, s0, m0)
        open_file(driver, server, shot, args.out)
        http_only(driver, server)
        errors = [e for e in driver.get_log("browser") if e["level"] == "SEVERE"]
        check(not errors, "no error in the browser console " + (json.dumps(errors) if errors else ""))
        check(driver.execute_script("return document.getElementById('error').hidden"), "no error shown")
        return 0
    finally:
        if driver:
            driver.quit()
        server.stop()
        if profile:
            shutil.rmtree(profile, ignore_errors=True)


def bench(driver, server, out_dir):
    """In-page latencies (apps/studio/web/studio_bench.js): clicks that add a constraint (each undone),
    a drag waiting for each frame, and a live drag (one pointer move per animation frame)."""
    def run_js(code):
        r = driver.execute_async_script(
            "const done = arguments[arguments.length - 1];" + code + ".then(done, (e) => done({error: String(e)}));")
        if "error" in r:
            raise Failure(code + ": " + r["error"])
        return r
    stats = server.get("/api/stats")
    load = [os.getloadavg()[0]]
    adds = run_js("studio.benchAdd({count: 12})")
    drag = run_js("studio.benchDrag({moves: 60})")
    live = run_js("studio.benchDrag({moves: 120, live: true})")
    load.append(os.getloadavg()[0])
    driver.save_screenshot(os.path.join(out_dir, "studio-bench.png"))
    print("BENCH " + json.dumps({"model": stats["name"], "load_average": load, "constraints": stats["constraints"],
                                 "triangles": stats["triangles"], "vertices": stats["vertices"],
                                 "browser": driver.capabilities.get("browserVersion"),
                                 "webgl": driver.execute_script(WEBGL_RENDERER),
                                 "antialias": driver.execute_script("return studio.renderer.getContextAttributes().antialias"),
                                 "low_res_interaction": driver.execute_script("return studio.lowResInteraction"),
                                 "add": adds["add"], "undo": adds["undo"], "target_after_add": adds["target_after_add"],
                                 "drag": drag, "live_drag": live}, indent=1))
    return 0


WEBGL_RENDERER = """const gl = studio.renderer.getContext(), e = gl.getExtension('WEBGL_debug_renderer_info');
return e ? gl.getParameter(e.UNMASKED_RENDERER_WEBGL) : gl.getParameter(gl.RENDERER);"""


def page_mesh_matches(driver, server):
    """The page's triangle slots (kept from the mesh deltas) hold the server's mesh: the same triangles,
    each corner equal to the server's vertex rounded to float32, the same orientation. Waits for the
    exact mesh the page asks for when idle (after approximate updates, docs/studio.md)."""
    wait_for("the target precision", lambda: server.get("/api/stats")["refined"], 300)
    wait_for("the exact mesh", lambda: driver.execute_script("return !studio.slots.approximate"))
    wait_for("the page to be idle", lambda: page_idle(driver))
    page = driver.execute_script(
        "const P = studio.slots.geometry.attributes.position.array, out = [];"
        "for (let s = 0; s < studio.slots.used; ++s) {"
        "  const t = Array.from(P.subarray(9 * s, 9 * s + 9));"
        "  if (t.some((x) => x !== 0)) out.push(t); }"
        "return out;")
    f32 = lambda x: struct.unpack("f", struct.pack("f", x))[0]

    def canonical(corners):  # a triangle as its corners from the smallest, orientation kept
        k = corners.index(min(corners))
        return tuple(corners[k:] + corners[:k])
    mesh = server.get("/api/mesh?format=indexed")
    vs = [tuple(f32(x) for x in v) for v in mesh["vertices"]]
    server_tris = sorted(canonical([vs[i] for i in t]) for t in mesh["triangles"])
    page_tris = sorted(canonical([tuple(t[3 * i:3 * i + 3]) for i in range(3)]) for t in page)
    return page_tris == server_tris


def page_constraints_match(driver, server):
    """The page's constraint list (kept from deltas) equals the server's, value for value."""
    page = driver.execute_script(
        "const c = studio.constraints, out = [];"
        "for (let i = 0; i < c.count; ++i) out.push(c.position(i).concat([c.value(i)]));"
        "return out;")
    server_list = [c["position"] + [c["value"]] for c in server.get("/api/state")["constraint_list"]]
    return page == server_list


def full_constraint_fetches(driver):
    """How many times the page asked for the constraint list with /api/constraints (a load, or out of step)."""
    return driver.execute_script(
        "return (api.counts.socket['/api/constraints'] || 0) + (api.counts.http['/api/constraints'] || 0)")


def requests_sent(driver, transport, route):
    """Requests of the page to `route` over `transport` ('socket' or 'http')."""
    return driver.execute_script("return api.counts[arguments[0]][arguments[1]] || 0", transport, route)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--vitri", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--model", default="")
    ap.add_argument("--precision", type=float, default=0.03)
    ap.add_argument("--bench", action="store_true")
    ap.add_argument("--api-bench", action="store_true", help="measure edit + delta round trips without a browser")
    ap.add_argument("--window", default="1280,800", help="browser window size W,H")
    ap.add_argument("--no-antialias", action="store_true", help="WebGL without antialiasing (page ?aa=0)")
    ap.add_argument("--query", default="", help="more page options, e.g. aa=1&lowres=0 (docs/studio.md)")
    ap.add_argument("--studio-args", default="", help="more vitri studio arguments (space-separated)")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    try:
        return run(args)
    except Failure as e:
        print("FAIL: " + str(e))
        return 1


if __name__ == "__main__":
    sys.exit(main())
