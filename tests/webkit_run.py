"""A second browser engine for the tests: WebKitGTK (Debian's ``gir1.2-webkit2-4.1``) driven through GObject
introspection, run by Debian's own ``/usr/bin/python3`` (``python3-gi``) under Xvfb (``xvfb-run``).

    xvfb-run -a /usr/bin/python3 tests/webkit_run.py URL SCENARIO_JS TIMEOUT_S

Loads URL in a WebKit2.WebView, then calls the JavaScript function body in the file SCENARIO_JS (it may
``await``; what it returns is the result) and prints one JSON line: {"result": …, "requests": [every URI the
page asked for], "error": null | "…"}. The engine version is in "engine". Nothing here is kinlib's: the tests
(tests/course/test_second_engine.py) give the scenario and judge the result.
"""

import json
import sys

import gi

gi.require_version("WebKit2", "4.1")
gi.require_version("Gtk", "3.0")
from gi.repository import GLib, Gtk, WebKit2  # noqa: E402


def main(url: str, scenario_path: str, timeout: float) -> int:
    scenario = open(scenario_path, encoding="utf-8").read()
    out = {"result": None, "requests": [], "error": None, "engine": None}
    out["engine"] = (
        f"WebKitGTK {WebKit2.get_major_version()}.{WebKit2.get_minor_version()}.{WebKit2.get_micro_version()}"
    )
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

    def on_request(_view, resource, _request):
        out["requests"].append(resource.get_uri()[:200])

    view.connect("resource-load-started", on_request)

    def done(_obj, res):
        try:
            value = view.call_async_javascript_function_finish(res)
            out["result"] = json.loads(value.to_json(0)) if value is not None and not value.is_undefined() else None
        except GLib.Error as e:
            out["error"] = e.message
        loop.quit()

    def on_load(_view, event):
        if event == WebKit2.LoadEvent.FINISHED:
            view.call_async_javascript_function(scenario, -1, None, None, None, None, done)

    def on_fail(_view, _event, uri, error):
        out["error"] = f"load failed: {uri}: {error.message}"
        loop.quit()
        return True

    def on_timeout():
        out["error"] = f"timed out after {timeout:g} s"
        loop.quit()
        return False

    view.connect("load-changed", on_load)
    view.connect("load-failed", on_fail)
    GLib.timeout_add(int(timeout * 1000), on_timeout)
    view.load_uri(url)
    loop.run()
    print(json.dumps(out))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1], sys.argv[2], float(sys.argv[3])))
