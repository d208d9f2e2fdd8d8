//! The console in a real browser: `pushbot console` on the built-in target, driven by Debian's
//! headless Chromium over the DevTools protocol (`headless_chrome`), judged by the simulator's
//! truth (`/api/truth`). An operator's clicks: pick an object, click its goal on the table,
//! Plan, Run; the emergency stop mid-push; a goal inside a wall; a second browser that only
//! watches; a request without the token.
//!
//! Needs `chromium` (the test command installs it); `PUSHBOT_CONSOLE_SHOT=FILE` saves a
//! screenshot of the first test's page after its delivery.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::{Mutex, OnceLock};
use std::time::{Duration, Instant};

use headless_chrome::browser::tab::point::Point;
use headless_chrome::{Browser, LaunchOptions, Tab};
use serde_json::Value;

/// One console at a time: each runs a simulated world and a renderer, and the timings of one
/// should not depend on another's load.
static ONE_AT_A_TIME: Mutex<()> = Mutex::new(());

const TOKEN: &str = "0123456789abcdef0123456789abcdef";

/// A running `pushbot console`.
struct Console {
    child: Child,
    addr: SocketAddr,
    url: String,
    dir: PathBuf,
}

/// The consoles' folder, shared by this process's tests so that the strategy the first one
/// collects for the object is the one the next loads.
fn shared_dir() -> PathBuf {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let d =
            Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("console-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).expect("the consoles' folder");
        d
    })
    .clone()
}

impl Console {
    fn start(scene: &str, listen: &str, sim_speed: &str) -> Console {
        let dir = shared_dir();
        let mut child = Command::new(pushbot_tests::bin("pushbot"))
            .args(["console", "--scene", scene, "--listen", listen, "--dir"])
            .arg(&dir)
            .args(["--sim-speed", sim_speed])
            .env("PUSHBOT_CONSOLE_TOKEN", TOKEN)
            .env_remove("PUSHBOT_LOG")
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .expect("start pushbot console");
        let stdout = child.stdout.take().expect("stdout");
        let (tx, rx) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            for line in BufReader::new(stdout).lines().map_while(Result::ok) {
                let _ = tx.send(line);
            }
        });
        let line = rx
            .recv_timeout(Duration::from_secs(120))
            .expect("the console prints its address");
        let url = line
            .strip_prefix("pushbot console: ")
            .unwrap_or_else(|| panic!("unexpected first line {line:?}"))
            .to_string();
        assert!(url.ends_with(&format!("?token={TOKEN}")), "{url}");
        let hostport = url
            .trim_start_matches("http://")
            .split('/')
            .next()
            .expect("host:port");
        let port: u16 = hostport.rsplit(':').next().unwrap().parse().unwrap();
        Console {
            child,
            addr: SocketAddr::from(([127, 0, 0, 1], port)),
            url,
            dir,
        }
    }

    /// `GET path` with the token; the JSON it answers.
    fn get(&self, path: &str) -> Value {
        let (code, body) = http(self.addr, "GET", path, Some(TOKEN));
        assert_eq!(code, 200, "GET {path}: {body}");
        serde_json::from_str(&body).unwrap_or_else(|e| panic!("GET {path}: {e}: {body}"))
    }

    fn truth(&self) -> Value {
        self.get("/api/truth")
    }

    fn commands_sent(&self) -> u64 {
        self.get("/api/state")["link"]["commands_sent"]
            .as_u64()
            .expect("commands_sent")
    }
}

impl Drop for Console {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// One HTTP/1.1 request to `addr` (the token as a bearer, when given): status and body.
fn http(addr: SocketAddr, method: &str, path: &str, token: Option<&str>) -> (u16, String) {
    let mut s = TcpStream::connect_timeout(&addr, Duration::from_secs(5)).expect("connect");
    s.set_read_timeout(Some(Duration::from_secs(30))).unwrap();
    let auth = token.map_or(String::new(), |t| format!("authorization: Bearer {t}\r\n"));
    let body = if method == "POST" { "{}" } else { "" };
    write!(
        s,
        "{method} {path} HTTP/1.1\r\nhost: {addr}\r\n{auth}x-pushbot-client: tester\r\n\
         content-type: application/json\r\ncontent-length: {}\r\nconnection: close\r\n\r\n{body}",
        body.len()
    )
    .expect("send");
    let mut raw = String::new();
    s.read_to_string(&mut raw).expect("read");
    let code = raw
        .split_whitespace()
        .nth(1)
        .and_then(|c| c.parse().ok())
        .unwrap_or_else(|| panic!("no status line in {raw:?}"));
    let body = raw
        .split_once("\r\n\r\n")
        .map_or("", |(_, b)| b)
        .to_string();
    (code, body)
}

fn browser() -> Browser {
    let path = ["/usr/bin/chromium", "/usr/bin/chromium-browser"]
        .into_iter()
        .map(std::path::PathBuf::from)
        .find(|p| p.exists());
    Browser::new(
        LaunchOptions::default_builder()
            .path(path)
            .sandbox(false)
            .window_size(Some((1400, 900)))
            .idle_browser_timeout(Duration::from_secs(600))
            .build()
            .expect("launch options"),
    )
    .expect("start headless Chromium (apt install chromium)")
}

/// Open the console's page and wait until it is interactive; how long that took, in ms.
fn open(tab: &Tab, url: &str) -> f64 {
    tab.set_default_timeout(Duration::from_secs(60));
    tab.navigate_to(url).expect("navigate");
    tab.wait_until_navigated().expect("navigated");
    tab.wait_for_element("body[data-ready='1']")
        .expect("the page gets ready");
    eval(tab, "window.pushbotReadyMs")
        .as_f64()
        .expect("ready ms")
}

/// Evaluate `js` in the page (awaiting a promise); its JSON value.
fn eval(tab: &Tab, js: &str) -> Value {
    let wrapped = format!("(async () => JSON.stringify(await ({js})))()");
    let r = tab.evaluate(&wrapped, true).expect("evaluate");
    match r.value {
        Some(Value::String(s)) => serde_json::from_str(&s).unwrap_or(Value::Null),
        _ => Value::Null,
    }
}

fn text(tab: &Tab, id: &str) -> String {
    eval(tab, &format!("document.getElementById('{id}').textContent"))
        .as_str()
        .unwrap_or_default()
        .to_string()
}

/// Pick `value` in the select `id`, as a user does.
fn pick(tab: &Tab, id: &str, value: &str) {
    let ok = eval(
        tab,
        &format!(
            "(() => {{ const s = document.getElementById('{id}');
                 if (![...s.options].some(o => o.value === '{value}')) return false;
                 s.value = '{value}'; s.dispatchEvent(new Event('change')); return true; }})()"
        ),
    );
    assert_eq!(ok, Value::Bool(true), "no option {value} in #{id}");
}

/// Click the table at (x, y) metres.
fn click_table(tab: &Tab, x: f64, y: f64) {
    let p = eval(tab, &format!("window.pushbotView.metresToClient({x}, {y})"));
    let (px, py) = (p[0].as_f64().unwrap(), p[1].as_f64().unwrap());
    tab.click_point(Point { x: px, y: py }).expect("click");
    let g = eval(tab, "window.pushbotView.goal()");
    let (gx, gy) = (g["x"].as_f64().unwrap(), g["y"].as_f64().unwrap());
    assert!(
        (gx - x).abs() < 0.005 && (gy - y).abs() < 0.005,
        "clicked ({x}, {y}), the page placed the goal at ({gx}, {gy})"
    );
}

fn click(tab: &Tab, id: &str) {
    tab.find_element(&format!("#{id}"))
        .expect("button")
        .click()
        .expect("click");
}

fn wait_for(what: &str, limit: Duration, mut f: impl FnMut() -> bool) {
    let t0 = Instant::now();
    while !f() {
        assert!(t0.elapsed() < limit, "{what}: not within {limit:?}");
        std::thread::sleep(Duration::from_millis(100));
    }
}

fn object_xy(truth: &Value, id: &str) -> [f64; 2] {
    let o = truth["objects"]
        .as_array()
        .expect("objects")
        .iter()
        .find(|o| o[0] == id)
        .unwrap_or_else(|| panic!("no {id} in the truth"));
    [o[1][0].as_f64().unwrap(), o[1][1].as_f64().unwrap()]
}

fn wheels(truth: &Value) -> f64 {
    let w = &truth["wheel_speed"];
    w[0].as_f64()
        .unwrap()
        .abs()
        .max(w[1].as_f64().unwrap().abs())
}

#[test]
fn a_goal_clicked_on_the_table_is_planned_run_and_reached() {
    let _one = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let _limit = pushbot_tests::WallLimit::arm("console delivery", Duration::from_secs(600));
    let console = Console::start("lau-irregular", "127.0.0.1:0", "4");
    let browser = browser();
    let tab = browser.new_tab().expect("tab");
    let ready_ms = open(&tab, &console.url);
    println!("page interactive after {ready_ms:.0} ms");
    assert!(
        text(&tab, "role").contains("you control"),
        "{}",
        text(&tab, "role")
    );
    // The camera's stream reaches the page.
    std::thread::sleep(Duration::from_secs(3));
    let fps = eval(&tab, "window.pushbotFps").as_f64().unwrap_or(0.0);
    println!("camera view: {fps} frames/s");
    assert!(fps >= 3.0, "the camera view shows {fps} frames/s");

    pick(&tab, "task", "deliver");
    pick(&tab, "object", "object");
    pick(&tab, "method", "learned");
    let goal = [1.0, 0.6];
    click_table(&tab, goal[0], goal[1]);
    let sent = console.commands_sent();
    click(&tab, "plan");
    wait_for("the plan is drawn", Duration::from_secs(300), || {
        !eval(&tab, "window.pushbotView.plan()").is_null() || !text(&tab, "error").is_empty()
    });
    assert_eq!(text(&tab, "error"), "", "planning failed");
    let plan = eval(&tab, "window.pushbotView.plan()");
    assert!(
        plan["paths"].as_array().is_some_and(|p| !p.is_empty()),
        "{plan}"
    );
    assert_eq!(console.commands_sent(), sent, "planning moved the robot");

    click(&tab, "run");
    wait_for("the run starts", Duration::from_secs(30), || {
        text(&tab, "status").starts_with("running") || !text(&tab, "runs").contains("none")
    });
    wait_for("the run ends", Duration::from_secs(400), || {
        text(&tab, "runs").contains("deliver")
    });
    let runs = text(&tab, "runs");
    assert!(runs.contains('✓'), "the run failed: {runs}");
    let truth = console.truth();
    let at = object_xy(&truth, "object");
    let miss = (at[0] - goal[0]).hypot(at[1] - goal[1]);
    println!("object's marker {:.1} mm from the clicked goal", miss * 1e3);
    // The run's folder (the page links its report): its summary says the radius it was
    // judged by.
    let link = eval(
        &tab,
        "document.querySelector('#runs a[href$=\"report.html\"]').getAttribute('href')",
    );
    let href = link.as_str().expect("a report link").to_string();
    let name = href.split('/').nth(3).expect("/api/runs/NAME/report.html");
    let run = console.dir.join("runs").join(name);
    for f in ["run.mcap", "report.html", "run.log", "summary.json"] {
        assert!(run.join(f).is_file(), "{} has no {f}", run.display());
    }
    let summary: Value =
        serde_json::from_str(&std::fs::read_to_string(run.join("summary.json")).unwrap()).unwrap();
    let radius = summary["success_radius_m"]
        .as_f64()
        .or_else(|| summary["result"]["success_radius_m"].as_f64())
        .unwrap_or(0.022);
    assert!(
        miss <= radius,
        "the object ended {:.1} mm from the goal (radius {:.1} mm)",
        miss * 1e3,
        radius * 1e3
    );
    // The page serves the report it links.
    let (code, body) = http(console.addr, "GET", &href, Some(TOKEN));
    assert_eq!(code, 200, "{href}");
    assert!(
        body.contains("<html") || body.contains("<!doctype"),
        "{href}"
    );
    if let Ok(path) = std::env::var("PUSHBOT_CONSOLE_SHOT") {
        let png = tab
            .capture_screenshot(
                headless_chrome::protocol::cdp::Page::CaptureScreenshotFormatOption::Png,
                None,
                None,
                true,
            )
            .expect("screenshot");
        std::fs::write(&path, png).expect("write the screenshot");
    }
}

#[test]
fn the_emergency_stop_stops_the_wheels_mid_push() {
    let _one = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let _limit = pushbot_tests::WallLimit::arm("console emergency stop", Duration::from_secs(600));
    let console = Console::start("lau-irregular", "127.0.0.1:0", "1");
    let browser = browser();
    let tab = browser.new_tab().expect("tab");
    open(&tab, &console.url);
    pick(&tab, "task", "deliver");
    pick(&tab, "object", "object");
    pick(&tab, "method", "learned");
    click_table(&tab, 1.2, 0.5);
    click(&tab, "run");
    // Mid-push: the wheels turn and the object has begun to move.
    let start = object_xy(&console.truth(), "object");
    wait_for("the push begins", Duration::from_secs(240), || {
        let t = console.truth();
        let o = object_xy(&t, "object");
        wheels(&t) > 1.0 && (o[0] - start[0]).hypot(o[1] - start[1]) > 0.005
    });
    let before = console.truth();
    assert!(wheels(&before) > 1.0, "{before}");
    let t0 = before["t"].as_f64().unwrap();
    // The keyboard's emergency stop (Space), as an operator hits it.
    tab.press_key(" ").expect("press Space");
    // Stopped: both wheels' rims slower than 5 mm/s (duty 0 brakes the motors through their
    // back-EMF; the speed decays exponentially to zero).
    let wheel_radius = pushbot_world::Scene::preset("lau-irregular")
        .expect("preset")
        .robot
        .wheel_radius;
    let still = 0.005 / wheel_radius;
    let mut stopped_at = None;
    let deadline = Instant::now() + Duration::from_secs(5);
    while Instant::now() < deadline {
        let t = console.truth();
        if wheels(&t) < still {
            stopped_at = Some(t["t"].as_f64().unwrap());
            break;
        }
    }
    let t1 = stopped_at.expect("the wheels stop");
    wait_for(
        "the page hears the robot's answer",
        Duration::from_secs(5),
        || !eval(&tab, "window.pushbotEstop").is_null(),
    );
    let ack = eval(&tab, "window.pushbotEstop.robot_time_s")
        .as_f64()
        .unwrap_or(f64::NAN);
    println!(
        "wheels stopped {:.0} ms of robot time after the key (the robot had it after {:.0} ms)",
        (t1 - t0) * 1e3,
        (ack - t0) * 1e3
    );
    // Two budgets: the way from the key to the robot (browser, socket, host, serial line: on a
    // loaded machine tens of ms), and the robot's own stop, which cuts the duty at once and
    // leaves the rest to the motors' back-EMF braking (about 200 ms from pushing speed).
    assert!(
        ack - t0 <= 0.15,
        "the robot had the emergency stop {:.0} ms after the key",
        (ack - t0) * 1e3
    );
    assert!(
        t1 - ack <= 0.25,
        "the wheels stopped {:.0} ms after the robot had the emergency stop",
        (t1 - ack) * 1e3
    );
    // They stay stopped, the task ends, and the page says why.
    std::thread::sleep(Duration::from_millis(1500));
    let later = console.truth();
    assert!(wheels(&later) < 0.01, "{later}");
    wait_for("the page shows the fault", Duration::from_secs(10), || {
        let l = text(&tab, "link");
        l.contains("EMERGENCY") || l.contains("Estop") || l.contains("emergency")
    });
    wait_for("the run ends", Duration::from_secs(60), || {
        text(&tab, "runs").contains("deliver")
    });
    assert!(text(&tab, "runs").contains('✗'), "{}", text(&tab, "runs"));
}

#[test]
fn a_goal_inside_a_wall_is_refused_on_the_page_and_nothing_moves() {
    let _one = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let _limit = pushbot_tests::WallLimit::arm("console goal in a wall", Duration::from_secs(300));
    let console = Console::start("lau-obstacles", "127.0.0.1:0", "1");
    let browser = browser();
    let tab = browser.new_tab().expect("tab");
    open(&tab, &console.url);
    pick(&tab, "task", "deliver");
    pick(&tab, "object", "object");
    pick(&tab, "method", "dipole");
    let sent = console.commands_sent();
    let robot = console.truth()["robot"].clone();
    // The wall of lau-obstacles: x 0.78 … 0.88, y 0.55 … 1.20.
    click_table(&tab, 0.83, 0.9);
    for button in ["plan", "run"] {
        click(&tab, button);
        wait_for("an error on the page", Duration::from_secs(30), || {
            !text(&tab, "error").is_empty()
        });
        let e = text(&tab, "error");
        assert!(e.contains("obstacle"), "{button}: {e}");
        eval(
            &tab,
            "(document.getElementById('error').textContent = '', 0)",
        );
    }
    std::thread::sleep(Duration::from_secs(1));
    assert_eq!(console.commands_sent(), sent, "a command reached the robot");
    let now = console.truth()["robot"].clone();
    assert_eq!(now, robot, "the robot moved");
    assert!(
        text(&tab, "log").contains("obstacle"),
        "{}",
        text(&tab, "log")
    );
}

/// This machine's address on its first non-loopback interface (the default route's), if any.
fn other_address() -> Option<std::net::IpAddr> {
    let s = std::net::UdpSocket::bind("0.0.0.0:0").ok()?;
    s.connect("10.255.255.255:9").ok()?;
    let ip = s.local_addr().ok()?.ip();
    (!ip.is_loopback() && !ip.is_unspecified()).then_some(ip)
}

#[test]
fn without_the_token_everything_is_refused_and_a_second_browser_only_watches() {
    let _one = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let _limit = pushbot_tests::WallLimit::arm("console security", Duration::from_secs(300));
    let console = Console::start("lau-obstacles", "0.0.0.0:0", "1");
    let ip = other_address().unwrap_or(std::net::Ipv4Addr::LOCALHOST.into());
    let there = SocketAddr::new(ip, console.addr.port());
    println!("asking {there} without the token");
    for (method, path) in [
        ("GET", "/"),
        ("GET", "/api/scene"),
        ("GET", "/api/state"),
        ("GET", "/api/truth"),
        ("GET", "/api/ws?client=x"),
        ("POST", "/api/run"),
        ("POST", "/api/plan"),
        ("POST", "/api/claim"),
        ("POST", "/api/estop"),
        ("POST", "/api/clear"),
        ("GET", "/api/runs/x/report.html"),
    ] {
        let (code, _) = http(there, method, path, None);
        assert_eq!(code, 401, "{method} {path} without the token");
        let (code, _) = http(there, method, path, Some("not-the-token"));
        assert_eq!(code, 401, "{method} {path} with a wrong token");
    }
    let (code, _) = http(there, "GET", "/api/scene", Some(TOKEN));
    assert_eq!(code, 200, "the token opens it");

    let browser = browser();
    let first = browser.new_tab().expect("tab");
    open(&first, &console.url.replace("127.0.0.1", &ip.to_string()));
    assert!(text(&first, "role").contains("you control"));
    let second = browser.new_tab().expect("tab");
    open(&second, &console.url);
    wait_for(
        "the second page knows it watches",
        Duration::from_secs(10),
        || text(&second, "role").contains("watching"),
    );
    // The watcher's buttons are disabled; a Run it sends anyway is refused (409).
    assert_eq!(
        eval(&second, "document.getElementById('run').disabled"),
        Value::Bool(true)
    );
    pick(&second, "task", "deliver");
    pick(&second, "object", "object");
    pick(&second, "method", "dipole");
    click_table(&second, 1.2, 0.4);
    let sent = console.commands_sent();
    let refused = eval(
        &second,
        "fetch('/api/run', {method: 'POST', headers, body: JSON.stringify(request())})
           .then(async r => [r.status, (await r.json()).error])",
    );
    assert_eq!(refused[0], 409, "{refused}");
    assert!(
        refused[1]
            .as_str()
            .unwrap_or_default()
            .contains("another browser"),
        "{refused}"
    );
    std::thread::sleep(Duration::from_millis(500));
    assert_eq!(
        console.commands_sent(),
        sent,
        "the watcher's Run moved the robot"
    );
    assert!(
        console.get("/api/state")["running"].is_null(),
        "a task runs after the watcher's Run"
    );
}
