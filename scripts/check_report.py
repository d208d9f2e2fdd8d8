#!/usr/bin/env python3
"""Opens a pushbot report (report.html) in a real headless browser (Debian's `chromium`) and
checks that every figure was drawn at a non-zero size from an image that loaded, that every
figure has a caption, that no table cell holds raw JSON, that no table labels a row or a column
with a field name (snake_case) or shows a value with more than four significant digits, and
that the page logged no error.

    python3 scripts/check_report.py DIR/report.html
    python3 scripts/check_report.py --self-test DIR/report.html   # also: a broken copy fails

How: a page `check.html` written beside the report loads it in an iframe, measures each
figure's image (getBoundingClientRect, naturalWidth) and writes the results into its own DOM;
`chromium --headless --dump-dom` prints that DOM. The browser's console (errors, resources
that failed to load) comes on its stderr. Prints one JSON object; exit status 1 on a failure.
"""

import base64
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile

CHECK_PAGE = """<!doctype html><html><head><meta charset="utf-8"></head><body>
<pre id="out">pending</pre>
<iframe id="f" src="%s" style="width:1200px;height:900px"></iframe>
<script>
const errors = [];
window.addEventListener('error', e => errors.push('check page: ' + (e.message || e)), true);
const f = document.getElementById('f');
f.addEventListener('load', () => {
  const d = f.contentDocument;
  const figures = [...d.querySelectorAll('figure')].map(fig => {
    const img = fig.querySelector('img');
    // The drawn size inside the border (a squashed image keeps its border).
    const r = img ? {width: img.clientWidth, height: img.clientHeight} : {width: 0, height: 0};
    const cap = fig.querySelector('figcaption');
    return {src: img ? img.getAttribute('src') : null, width: r.width, height: r.height,
            natural: img ? img.naturalWidth : 0, caption: cap ? cap.textContent.trim() : ''};
  });
  const cells = [...d.querySelectorAll('td')].map(td => td.textContent.trim())
    .filter(t => /^[\\[{].*[\\]}]$/.test(t));
  // Every header, and every cell that holds no table of its own (its text is one value).
  const headers = [...d.querySelectorAll('th')].map(th => th.textContent.trim());
  const leaves = [...d.querySelectorAll('td')].filter(td => !td.querySelector('table'))
    .map(td => td.textContent.trim());
  const out = JSON.stringify({title: d.title, figures, json_cells: cells, headers, leaves, errors});
  document.getElementById('out').textContent = 'RESULT:' + btoa(unescape(encodeURIComponent(out)));
});
</script></body></html>
"""

FLAGS = [
    "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
    "--disable-background-networking", "--disable-component-update", "--disable-sync",
    "--allow-file-access-from-files", "--enable-logging=stderr", "--v=0",
    "--virtual-time-budget=15000", "--dump-dom",
]


def browser():
    for name in ["chromium", "chromium-browser", "google-chrome"]:
        path = shutil.which(name)
        if path:
            return path
    sys.exit("check_report: no chromium on PATH (scripts/test-all.sh installs Debian's chromium)")


SNAKE = re.compile(r"\b[a-z][a-z0-9]*_[a-z0-9_]+\b")
DECIMAL = re.compile(r"\d+\.\d+")


def too_precise(text):
    """Whether a cell shows a decimal number of more than four significant digits."""
    return any(len(n.replace(".", "").lstrip("0")) > 4 for n in DECIMAL.findall(text))


def check(report):
    report = os.path.abspath(report)
    folder = os.path.dirname(report)
    page = os.path.join(folder, "check-report.html")
    with open(page, "w") as f:
        f.write(CHECK_PAGE % os.path.basename(report))
    profile = tempfile.mkdtemp(prefix="pushbot-chromium-")
    try:
        run = subprocess.run(
            [browser(), *FLAGS, f"--user-data-dir={profile}", "file://" + page],
            capture_output=True, text=True, timeout=180)
    finally:
        shutil.rmtree(profile, ignore_errors=True)
        os.remove(page)
    m = re.search(r"RESULT:([A-Za-z0-9+/=]+)", run.stdout)
    failures = []
    if not m:
        return {"report": report, "failures": ["the check page did not finish"],
                "stderr": run.stderr[-2000:]}
    result = json.loads(base64.b64decode(m.group(1)).decode())
    # Console messages of the report page: errors and resources that failed to load.
    console = [l for l in run.stderr.splitlines() if "CONSOLE" in l and
               ("rror" in l or "Failed to load" in l or "Uncaught" in l)]
    failures += [f"console: {l.strip()}" for l in console]
    failures += [f"page error: {e}" for e in result["errors"]]
    if not result["figures"]:
        failures.append("the report has no figure")
    for fig in result["figures"]:
        if not (fig["width"] > 0 and fig["height"] > 0 and fig["natural"] > 0):
            failures.append(f"figure {fig['src']}: drawn {fig['width']}x{fig['height']}, "
                            f"image width {fig['natural']}")
        if not fig["caption"]:
            failures.append(f"figure {fig['src']}: no caption")
    failures += [f"raw JSON in a table cell: {c[:80]}" for c in result["json_cells"]]
    # Tables read like a product's: labels, not field names; values rounded.
    failures += [f"a field name for a label: {h!r}" for h in result.pop("headers")
                 if SNAKE.search(h)]
    failures += [f"a value with more than 4 significant digits: {c!r}"
                 for c in result.pop("leaves") if too_precise(c)]
    result.update(report=report, failures=failures)
    return result


def main(argv):
    self_test = "--self-test" in argv
    report = [a for a in argv if not a.startswith("--")][0]
    result = check(report)
    print(json.dumps(result, sort_keys=True))
    code = 1 if result["failures"] else 0
    if self_test:
        # The same report with one figure's image gone and one figure squashed must fail.
        with tempfile.TemporaryDirectory() as tmp:
            src = os.path.dirname(os.path.abspath(report))
            for name in os.listdir(src):
                if name.endswith((".html", ".svg", ".png")):
                    shutil.copy(os.path.join(src, name), tmp)
            html = open(os.path.join(tmp, "report.html")).read()
            imgs = re.findall(r'<img src="([^"]+)"', html)
            if len(imgs) < 2:
                print("self-test: the report needs two figures", file=sys.stderr)
                return 1
            os.remove(os.path.join(tmp, imgs[0]))
            html = html.replace(f'<img src="{imgs[1]}"', f'<img style="height:0" src="{imgs[1]}"', 1)
            # A raw field name and an unrounded value must fail too.
            html = html.replace("</table>", "<tr><th>final_distance_m</th><td>0.012834</td></tr></table>", 1)
            open(os.path.join(tmp, "report.html"), "w").write(html)
            broken = check(os.path.join(tmp, "report.html"))
            found = "\n".join(broken["failures"])
            if (imgs[0] not in found or imgs[1] not in found or "'final_distance_m'" not in found
                    or "'0.012834'" not in found):
                print(f"self-test: a broken report passed: {broken['failures']}", file=sys.stderr)
                code = 1
            else:
                print(f"self-test: a broken report fails as it should ({len(broken['failures'])} failures)")
    return code


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
