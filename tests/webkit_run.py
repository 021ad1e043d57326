"""A second browser engine for the tests: WebKitGTK (Debian's ``gir1.2-webkit2-4.1``) driven through GObject
introspection, run by Debian's own ``/usr/bin/python3`` (``python3-gi``) under Xvfb (``xvfb-run``).

    xvfb-run -a /usr/bin/python3 tests/webkit_run.py URL SCENARIO_JS TIMEOUT_S [URL SCENARIO_JS TIMEOUT_S ...]

For each triple in turn, in one WebKit2.WebView (one engine start for all of them): loads URL, then calls the
JavaScript function body in the file SCENARIO_JS (it may ``await``; what it returns is the result) and prints one
JSON line: {"result": …, "requests": [every URI the page asked for in this step], "error": null | "…",
"engine": the engine's version}. A step that fails to load or runs out of its TIMEOUT_S says so in "error" and
the next step still runs. Nothing here is kinlib's: the tests (tests/course/test_second_engine.py) give the
scenarios and judge the results.
"""

import json
import sys

import gi

gi.require_version("WebKit2", "4.1")
gi.require_version("Gtk", "3.0")
from gi.repository import GLib, Gtk, WebKit2  # noqa: E402


def main(steps: list) -> int:
    engine = f"WebKitGTK {WebKit2.get_major_version()}.{WebKit2.get_minor_version()}.{WebKit2.get_micro_version()}"
    Gtk.init([])
    win = Gtk.OffscreenWindow()
    view = WebKit2.WebView()
    settings = view.get_settings()
    settings.set_enable_developer_extras(True)
    settings.set_allow_file_access_from_file_urls(True)
    settings.set_enable_write_console_messages_to_stdout(False)
    view.set_size_request(1300, 1000)
    win.add(view)
    win.show_all()
    loop = GLib.MainLoop()
    state = {"step": -1, "out": None, "timer": None, "started": False}

    def finish():
        """Print the current step's line and start the next step (or stop)."""
        if state["timer"] is not None:
            GLib.source_remove(state["timer"])
            state["timer"] = None
        if state["out"] is not None:
            print(json.dumps(state["out"]), flush=True)
        state["step"] += 1
        if state["step"] >= len(steps):
            loop.quit()
            return
        url, scenario_path, timeout = steps[state["step"]]
        state["out"] = {"result": None, "requests": [], "error": None, "engine": engine}
        state["scenario"] = open(scenario_path, encoding="utf-8").read()
        state["started"] = False
        state["timer"] = GLib.timeout_add(int(timeout * 1000), on_timeout, state["step"], timeout)
        view.load_uri(url)

    def on_request(_view, resource, _request):
        if state["out"] is not None:
            state["out"]["requests"].append(resource.get_uri()[:200])

    def done(_obj, res, step):
        if step != state["step"]:  # the step ran out of time; its late answer is not this step's
            return
        try:
            value = view.call_async_javascript_function_finish(res)
            state["out"]["result"] = (
                json.loads(value.to_json(0)) if value is not None and not value.is_undefined() else None
            )
        except GLib.Error as e:
            state["out"]["error"] = e.message
        finish()

    def on_load(_view, event):
        if event == WebKit2.LoadEvent.FINISHED and not state["started"]:
            state["started"] = True
            view.call_async_javascript_function(state["scenario"], -1, None, None, None, None, done, state["step"])

    def on_fail(_view, _event, uri, error):
        state["out"]["error"] = f"load failed: {uri}: {error.message}"
        state["started"] = True
        GLib.idle_add(lambda: finish() and False)
        return True

    def on_timeout(step, timeout):
        if step == state["step"]:
            state["timer"] = None
            state["out"]["error"] = f"timed out after {timeout:g} s"
            finish()
        return False

    view.connect("resource-load-started", on_request)
    view.connect("load-changed", on_load)
    view.connect("load-failed", on_fail)
    GLib.idle_add(lambda: finish() and False)
    loop.run()
    return 0


if __name__ == "__main__":
    args = sys.argv[1:]
    if not args or len(args) % 3:
        sys.exit(__doc__)
    sys.exit(main([(args[i], args[i + 1], float(args[i + 2])) for i in range(0, len(args), 3)]))
