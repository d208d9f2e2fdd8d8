//! The console's router: the page, its JSON API and its WebSocket, every route behind the
//! token, every change behind the one controlling browser (the emergency stop excepted).

use std::collections::VecDeque;
use std::sync::mpsc::Sender;
use std::sync::{Arc, Mutex};

use axum::Router;
use axum::extract::ws::{Message, WebSocket, WebSocketUpgrade};
use axum::extract::{Path as UrlPath, Query, Request, State};
use axum::http::{HeaderMap, StatusCode, header};
use axum::middleware::{self, Next};
use axum::response::{IntoResponse, Response};
use axum::routing::{get, post};
use serde_json::{Value, json};

use super::ConsoleOptions;
use super::frames::Frames;
use super::request::{Context, TaskRequest, build};
use super::worker::{Job, Published};
use crate::exec::live::{Stopper, Watch};
use crate::task::session::Target;
use crate::task::{Control, TaskEvent};

/// The page, embedded in the binary.
const PAGE: &str = include_str!("page.html");

/// The console's state.
pub struct App {
    token: String,
    scene: Value,
    opts: ConsoleOptions,
    jobs: Mutex<Sender<Job>>,
    control: Mutex<Option<Control>>,
    /// The controlling browser's id and its open sockets.
    controller: Mutex<Option<(String, usize)>>,
    watch: Arc<Mutex<Watch>>,
    stopper: Stopper,
    target: Option<Arc<dyn Target>>,
    published: Arc<Mutex<Published>>,
    events: tokio::sync::broadcast::Sender<String>,
    log: Mutex<VecDeque<Value>>,
    plan: Mutex<Option<Value>>,
    frames: Frames,
    strategies: std::path::PathBuf,
}

/// What [`App::new`] is made of.
pub struct AppParts<'a> {
    /// The token every request carries.
    pub token: String,
    /// The console's options.
    pub opts: &'a ConsoleOptions,
    /// The worker's jobs.
    pub jobs: Sender<Job>,
    /// The robot's latest look.
    pub watch: Arc<Mutex<Watch>>,
    /// Stops the robot at once.
    pub stopper: Stopper,
    /// The built-in target, if that is the robot.
    pub target: Option<Arc<dyn Target>>,
    /// What the worker publishes.
    pub published: Arc<Mutex<Published>>,
    /// Every browser's events.
    pub events: tokio::sync::broadcast::Sender<String>,
    /// The camera's JPEG stream.
    pub frames: Frames,
}

fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
}

impl App {
    /// The state of a console.
    pub fn new(p: AppParts<'_>) -> App {
        let s = &p.opts.scene;
        let scene = json!({
            "name": s.name,
            "table": [s.table.width, s.table.height],
            "obstacles": s.obstacles.iter().map(|o| &o.outline).collect::<Vec<_>>(),
            "objects": s.objects.iter().map(|o| json!({
                "id": o.id,
                "outline": o.outline,
                "marker": o.marker.map(|m| [m.x, m.y]),
            })).collect::<Vec<_>>(),
            "goals": s.goals.iter().map(|g| json!({"id": g.object, "pose": [g.pose.x, g.pose.y, g.pose.theta]})).collect::<Vec<_>>(),
            "robot_radius": s.robot.bumper_radius,
            "tasks": if p.opts.rearrange.is_some() { vec!["rearrange", "deliver", "collect"] } else { vec!["deliver", "collect"] },
            "builtin": p.target.is_some(),
        });
        App {
            token: p.token,
            scene,
            opts: p.opts.clone(),
            jobs: Mutex::new(p.jobs),
            control: Mutex::new(None),
            controller: Mutex::new(None),
            watch: p.watch,
            stopper: p.stopper,
            target: p.target,
            published: p.published,
            events: p.events,
            log: Mutex::new(VecDeque::new()),
            plan: Mutex::new(None),
            frames: p.frames,
            strategies: p.opts.dir.join("strategies"),
        }
    }

    /// A task's event: into the log and to every browser.
    pub fn event(&self, e: &TaskEvent) {
        let v = serde_json::to_value(e).unwrap_or_default();
        if let TaskEvent::Plan { .. } = e {
            *lock(&self.plan) = Some(v.clone());
        }
        if !matches!(e, TaskEvent::Look { .. }) {
            let mut log = lock(&self.log);
            log.push_back(v.clone());
            while log.len() > 500 {
                log.pop_front();
            }
        }
        let _ = self
            .events
            .send(json!({"type": "event", "event": v}).to_string());
    }

    fn note(&self, text: &str) {
        self.event(&TaskEvent::Progress {
            note: text.into(),
            samples: None,
            streak: None,
        });
    }

    fn context(&self) -> Context<'_> {
        Context {
            scene: &self.opts.scene,
            rearrange: self.opts.rearrange.as_ref(),
            strategies: &self.strategies,
            builtin: self.target.is_some(),
            seed: self.opts.seed,
        }
    }

    fn is_controller(&self, client: &str) -> bool {
        lock(&self.controller)
            .as_ref()
            .is_some_and(|(c, _)| c == client)
    }

    fn state(&self, client: &str) -> Value {
        let t = self.stopper.telemetry();
        let stats = self.stopper.stats();
        let p = lock(&self.published);
        let watch = lock(&self.watch).clone();
        let control = lock(&self.control).clone();
        json!({
            "type": "state",
            "you_control": self.is_controller(client),
            "someone_controls": lock(&self.controller).is_some(),
            "running": p.running.as_ref().map(|(t, s)| json!({"task": t, "summary": s})),
            "paused": control.as_ref().is_some_and(Control::paused),
            "runs": p.runs,
            "link": {
                "port": self.stopper.path(),
                "connected": t.is_some(),
                "frames_sent": stats.frames_sent,
                "heartbeats_sent": stats.heartbeats_sent,
                "commands_sent": stats.frames_sent.saturating_sub(stats.heartbeats_sent),
                "retries": stats.retries,
                "frames_rejected": stats.frames_rejected,
                "recoveries": self.stopper.recoveries(),
            },
            "telemetry": t.map(|t| json!({
                "time_s": t.time_us as f64 * 1e-6,
                "mode": format!("{:?}", t.mode),
                "faults": crate::link::FaultNames(t.faults).to_string(),
                "emergency_stop": t.faults.contains(pushbot_protocol::Faults::EMERGENCY_STOP),
                "wheel_speed": t.wheel_speed,
                "bumper": t.bumper,
            })),
            "watch": watch,
        })
    }
}

/// The router.
pub fn router(app: Arc<App>) -> Router {
    Router::new()
        .route("/", get(page))
        .route("/api/scene", get(scene))
        .route("/api/state", get(state))
        .route("/api/claim", post(claim))
        .route("/api/plan", post(plan))
        .route("/api/run", post(run))
        .route("/api/pause", post(pause))
        .route("/api/resume", post(resume))
        .route("/api/stop", post(stop))
        .route("/api/estop", post(estop))
        .route("/api/clear", post(clear))
        .route("/api/truth", get(truth))
        .route("/api/runs/{name}/{file}", get(run_file))
        .route("/api/ws", get(ws))
        .layer(middleware::from_fn_with_state(Arc::clone(&app), auth))
        .with_state(app)
}

/// Equal, in time independent of where they differ.
fn same(a: &str, b: &str) -> bool {
    a.len() == b.len()
        && a.bytes()
            .zip(b.bytes())
            .fold(0u8, |acc, (x, y)| acc | (x ^ y))
            == 0
}

fn token_of(req: &Request) -> Option<String> {
    let q = req.uri().query().unwrap_or("");
    for kv in q.split('&') {
        if let Some(v) = kv.strip_prefix("token=") {
            return Some(v.to_string());
        }
    }
    let h = req.headers();
    if let Some(v) = h.get(header::AUTHORIZATION).and_then(|v| v.to_str().ok())
        && let Some(t) = v.strip_prefix("Bearer ")
    {
        return Some(t.trim().to_string());
    }
    h.get(header::COOKIE)
        .and_then(|v| v.to_str().ok())
        .and_then(|c| {
            c.split(';')
                .map(str::trim)
                .find_map(|kv| kv.strip_prefix("pushbot_token=").map(str::to_string))
        })
}

async fn auth(State(app): State<Arc<App>>, req: Request, next: Next) -> Response {
    match token_of(&req) {
        Some(t) if same(&t, &app.token) => next.run(req).await,
        _ => (
            StatusCode::UNAUTHORIZED,
            "pushbot console: this needs the token printed when the console started \
             (open the address it printed, with ?token=…)\n",
        )
            .into_response(),
    }
}

fn client(h: &HeaderMap) -> Result<String, Refusal> {
    match h.get("x-pushbot-client").and_then(|v| v.to_str().ok()) {
        Some(c)
            if !c.is_empty()
                && c.len() <= 64
                && c.chars().all(|ch| ch.is_ascii_alphanumeric() || ch == '-') =>
        {
            Ok(c.to_string())
        }
        _ => Err(refusal(
            StatusCode::BAD_REQUEST,
            "missing or bad x-pushbot-client header",
        )),
    }
}

fn refuse(code: StatusCode, msg: &str) -> Response {
    Refusal(code, msg.to_string()).into_response()
}

/// A refused request: its status and the message the page shows.
struct Refusal(StatusCode, String);

impl IntoResponse for Refusal {
    fn into_response(self) -> Response {
        (self.0, axum::Json(json!({"error": self.1}))).into_response()
    }
}

fn refusal(code: StatusCode, msg: &str) -> Refusal {
    Refusal(code, msg.to_string())
}

fn controller_only(app: &App, h: &HeaderMap) -> Result<String, Refusal> {
    let c = client(h)?;
    if app.is_controller(&c) {
        Ok(c)
    } else {
        Err(refusal(
            StatusCode::CONFLICT,
            "another browser controls the robot: this one watches",
        ))
    }
}

async fn page(State(app): State<Arc<App>>) -> Response {
    (
        [
            (header::CONTENT_TYPE, "text/html; charset=utf-8".to_string()),
            (
                header::SET_COOKIE,
                format!(
                    "pushbot_token={}; HttpOnly; SameSite=Strict; Path=/",
                    app.token
                ),
            ),
            (header::CACHE_CONTROL, "no-store".to_string()),
        ],
        PAGE,
    )
        .into_response()
}

async fn scene(State(app): State<Arc<App>>) -> Response {
    axum::Json(app.scene.clone()).into_response()
}

async fn state(State(app): State<Arc<App>>, h: HeaderMap) -> Response {
    let c = client(&h).unwrap_or_default();
    let mut s = app.state(&c);
    s["log"] = Value::Array(lock(&app.log).iter().cloned().collect());
    s["plan"] = lock(&app.plan).clone().unwrap_or(Value::Null);
    axum::Json(s).into_response()
}

async fn claim(State(app): State<Arc<App>>, h: HeaderMap) -> Response {
    let c = match client(&h) {
        Ok(c) => c,
        Err(r) => return r.into_response(),
    };
    let mut ctl = lock(&app.controller);
    match &*ctl {
        Some((holder, _)) if *holder != c => refuse(
            StatusCode::CONFLICT,
            "another browser controls the robot: this one watches",
        ),
        Some(_) => axum::Json(json!({"control": true})).into_response(),
        None => {
            *ctl = Some((c, 0));
            axum::Json(json!({"control": true})).into_response()
        }
    }
}

fn parse_task(body: &str) -> Result<TaskRequest, Refusal> {
    if body.len() > 64 * 1024 {
        return Err(refusal(
            StatusCode::PAYLOAD_TOO_LARGE,
            "the request is too large",
        ));
    }
    serde_json::from_str(body)
        .map_err(|e| refusal(StatusCode::BAD_REQUEST, &format!("a bad request: {e}")))
}

async fn built(app: &Arc<App>, body: &str) -> Result<crate::task::Task, Refusal> {
    let req = parse_task(body)?;
    let a = Arc::clone(app);
    tokio::task::spawn_blocking(move || build(&req, &a.context()))
        .await
        .map_err(|e| refusal(StatusCode::INTERNAL_SERVER_ERROR, &e.to_string()))?
        .map_err(|e| {
            app.note(&format!("refused: {e}"));
            refusal(StatusCode::UNPROCESSABLE_ENTITY, &e)
        })
}

async fn plan(State(app): State<Arc<App>>, h: HeaderMap, body: String) -> Response {
    if let Err(r) = controller_only(&app, &h) {
        return r.into_response();
    }
    let task = match built(&app, &body).await {
        Ok(t) => t,
        Err(r) => return r.into_response(),
    };
    if lock(&app.published).running.is_some() {
        return refuse(StatusCode::CONFLICT, "a task is running: stop it first");
    }
    let (tx, rx) = std::sync::mpsc::channel();
    if lock(&app.jobs).send(Job::Plan(Box::new(task), tx)).is_err() {
        return refuse(
            StatusCode::SERVICE_UNAVAILABLE,
            "the robot's worker has stopped",
        );
    }
    let got = tokio::task::spawn_blocking(move || rx.recv()).await;
    match got {
        Ok(Ok(Ok(ev))) => {
            app.event(&ev);
            axum::Json(json!({"plan": ev})).into_response()
        }
        Ok(Ok(Err(e))) => {
            app.note(&format!("no plan: {e}"));
            refuse(StatusCode::UNPROCESSABLE_ENTITY, &e)
        }
        _ => refuse(
            StatusCode::SERVICE_UNAVAILABLE,
            "the robot's worker has stopped",
        ),
    }
}

async fn run(State(app): State<Arc<App>>, h: HeaderMap, body: String) -> Response {
    if let Err(r) = controller_only(&app, &h) {
        return r.into_response();
    }
    if app
        .stopper
        .telemetry()
        .is_some_and(|t| t.faults.contains(pushbot_protocol::Faults::EMERGENCY_STOP))
    {
        return refuse(
            StatusCode::CONFLICT,
            "the emergency stop is latched: clear it first (Clear faults)",
        );
    }
    let task = match built(&app, &body).await {
        Ok(t) => t,
        Err(r) => return r.into_response(),
    };
    let control = Control::new();
    {
        let p = lock(&app.published);
        if p.running.is_some() {
            return refuse(StatusCode::CONFLICT, "a task is running: stop it first");
        }
    }
    *lock(&app.control) = Some(control.clone());
    let summary = task.summary();
    if lock(&app.jobs)
        .send(Job::Run(Box::new(task), control))
        .is_err()
    {
        return refuse(
            StatusCode::SERVICE_UNAVAILABLE,
            "the robot's worker has stopped",
        );
    }
    (
        StatusCode::ACCEPTED,
        axum::Json(json!({"started": summary})),
    )
        .into_response()
}

async fn pause(State(app): State<Arc<App>>, h: HeaderMap) -> Response {
    set_paused(&app, &h, true)
}

async fn resume(State(app): State<Arc<App>>, h: HeaderMap) -> Response {
    set_paused(&app, &h, false)
}

fn set_paused(app: &App, h: &HeaderMap, paused: bool) -> Response {
    if let Err(r) = controller_only(app, h) {
        return r.into_response();
    }
    match &*lock(&app.control) {
        Some(c) => {
            c.set_paused(paused);
            axum::Json(json!({"paused": paused})).into_response()
        }
        None => refuse(StatusCode::CONFLICT, "no task is running"),
    }
}

async fn stop(State(app): State<Arc<App>>, h: HeaderMap) -> Response {
    if let Err(r) = controller_only(&app, &h) {
        return r.into_response();
    }
    if let Some(c) = &*lock(&app.control) {
        c.cancel();
    }
    let s = app.stopper.clone();
    let r = tokio::task::spawn_blocking(move || s.stop()).await;
    app.note("stop pressed");
    match r {
        Ok(Ok(_)) => axum::Json(json!({"stopped": true})).into_response(),
        Ok(Err(e)) => refuse(StatusCode::BAD_GATEWAY, &format!("{e:#}")),
        Err(e) => refuse(StatusCode::INTERNAL_SERVER_ERROR, &e.to_string()),
    }
}

/// The emergency stop: any browser may press it. The motors are cut first, then the task told.
async fn estop(State(app): State<Arc<App>>) -> Response {
    let s = app.stopper.clone();
    let cut = tokio::task::spawn_blocking(move || s.emergency_stop());
    if let Some(c) = &*lock(&app.control) {
        c.emergency();
    }
    let r = cut.await;
    app.note("EMERGENCY STOP pressed");
    match r {
        Ok(Ok(t)) => {
            axum::Json(json!({"emergency_stop": true, "robot_time_s": t.time_us as f64 * 1e-6}))
                .into_response()
        }
        Ok(Err(e)) => refuse(StatusCode::BAD_GATEWAY, &format!("{e:#}")),
        Err(e) => refuse(StatusCode::INTERNAL_SERVER_ERROR, &e.to_string()),
    }
}

async fn clear(State(app): State<Arc<App>>, h: HeaderMap) -> Response {
    if let Err(r) = controller_only(&app, &h) {
        return r.into_response();
    }
    let s = app.stopper.clone();
    match tokio::task::spawn_blocking(move || s.clear_faults()).await {
        Ok(Ok(f)) => {
            axum::Json(json!({"faults": crate::link::FaultNames(f).to_string()})).into_response()
        }
        Ok(Err(e)) => refuse(StatusCode::BAD_GATEWAY, &format!("{e:#}")),
        Err(e) => refuse(StatusCode::INTERNAL_SERVER_ERROR, &e.to_string()),
    }
}

/// The simulator's truth (the built-in target only).
async fn truth(State(app): State<Arc<App>>) -> Response {
    match app.target.as_ref().and_then(|t| t.truth()) {
        Some(t) => axum::Json(t).into_response(),
        None => refuse(
            StatusCode::NOT_FOUND,
            "a real robot has no simulator's truth",
        ),
    }
}

/// A finished run's file: its report, recording, log, summary or figure.
async fn run_file(
    State(app): State<Arc<App>>,
    UrlPath((name, file)): UrlPath<(String, String)>,
) -> Response {
    let known = lock(&app.published).runs.iter().any(|r| r.name == name);
    let kind = match file.as_str() {
        "report.html" => "text/html; charset=utf-8",
        "run.svg" => "image/svg+xml",
        "summary.json" => "application/json",
        "run.log" => "text/plain; charset=utf-8",
        "run.mcap" => "application/octet-stream",
        _ => return refuse(StatusCode::NOT_FOUND, "no such file of a run"),
    };
    if !known {
        return refuse(StatusCode::NOT_FOUND, "no such run");
    }
    let path = app.opts.dir.join("runs").join(&name).join(&file);
    match tokio::task::spawn_blocking(move || std::fs::read(&path))
        .await
        .unwrap_or_else(|e| Err(std::io::Error::other(e.to_string())))
    {
        Ok(bytes) => {
            let mut r = ([(header::CONTENT_TYPE, kind)], bytes).into_response();
            if file == "run.mcap" {
                r.headers_mut().insert(
                    header::CONTENT_DISPOSITION,
                    header::HeaderValue::from_static("attachment; filename=\"run.mcap\""),
                );
            }
            r
        }
        Err(e) => refuse(StatusCode::NOT_FOUND, &format!("{file}: {e}")),
    }
}

#[derive(serde::Deserialize)]
struct WsQuery {
    client: Option<String>,
}

async fn ws(
    State(app): State<Arc<App>>,
    Query(q): Query<WsQuery>,
    up: WebSocketUpgrade,
) -> Response {
    let client = q
        .client
        .filter(|c| c.len() <= 64 && c.chars().all(|ch| ch.is_ascii_alphanumeric() || ch == '-'))
        .unwrap_or_default();
    up.on_upgrade(move |socket| stream(app, socket, client))
}

/// One browser's socket: the state four times a second, the overlay when a look changes it,
/// every event, and the camera's JPEG frames.
async fn stream(app: Arc<App>, mut socket: WebSocket, client: String) {
    if let Some((c, n)) = &mut *lock(&app.controller)
        && *c == client
    {
        *n += 1;
    }
    let mut events = app.events.subscribe();
    let (mut frames, _watcher) = app.frames.watch();
    let mut tick = tokio::time::interval(std::time::Duration::from_millis(250));
    let mut looks = u64::MAX;
    loop {
        tokio::select! {
            _ = tick.tick() => {
                let s = app.state(&client).to_string();
                if socket.send(Message::Text(s.into())).await.is_err() { break; }
                let (n, svg) = { let w = lock(&app.watch); (w.looks, w.overlay_svg.clone()) };
                if n != looks {
                    looks = n;
                    let m = json!({"type": "overlay", "svg": svg}).to_string();
                    if socket.send(Message::Text(m.into())).await.is_err() { break; }
                }
            }
            e = events.recv() => {
                match e {
                    Ok(m) => if socket.send(Message::Text(m.into())).await.is_err() { break; },
                    Err(tokio::sync::broadcast::error::RecvError::Lagged(_)) => {}
                    Err(_) => break,
                }
            }
            changed = frames.changed() => {
                if changed.is_err() { break; }
                let jpeg = frames.borrow_and_update().clone();
                if let Some(j) = jpeg
                    && socket.send(Message::Binary(j.to_vec().into())).await.is_err() { break; }
            }
            msg = socket.recv() => {
                match msg {
                    Some(Ok(Message::Close(_))) | None | Some(Err(_)) => break,
                    _ => {}
                }
            }
        }
    }
    let mut ctl = lock(&app.controller);
    if let Some((c, n)) = &mut *ctl
        && *c == client
    {
        *n = n.saturating_sub(1);
        if *n == 0 {
            // The controlling browser went away: control is free for the next one.
            *ctl = None;
        }
    }
}
