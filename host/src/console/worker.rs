//! The console's worker: the one thread that owns the robot's [`Session`]. It runs the tasks
//! the page starts, one at a time, each into its own run folder, and between tasks keeps looking
//! so the page shows the table as it is (a box moved by hand shows where it went). Everything
//! else of the console only reads what it publishes, or stops the robot through a
//! [`crate::exec::live::Stopper`].

use std::path::PathBuf;
use std::sync::mpsc::{Receiver, RecvTimeoutError, Sender};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use crate::task::folder::RunFolder;
use crate::task::{Control, EventSink, Session, Task, TaskEvent};

/// What the worker is asked to do.
pub enum Job {
    /// Plan `task` from the observed table; the plan (or why not) goes back on the channel.
    Plan(Box<Task>, Sender<Result<TaskEvent, String>>),
    /// Run `task` under `control`.
    Run(Box<Task>, Control),
}

/// A finished run, for the page's list.
#[derive(Debug, Clone, serde::Serialize)]
pub struct RunInfo {
    /// The folder's name under the console's runs folder.
    pub name: String,
    /// Which task.
    pub task: String,
    /// It reached its goal.
    pub success: bool,
    /// How it ended.
    pub message: String,
}

/// What the worker publishes.
#[derive(Debug, Default)]
pub struct Published {
    /// The task running, if any: its name and summary.
    pub running: Option<(String, String)>,
    /// Finished runs, newest last.
    pub runs: Vec<RunInfo>,
}

/// Run the worker until the job channel closes.
pub fn work(
    mut session: Session,
    jobs: Receiver<Job>,
    runs_dir: PathBuf,
    published: Arc<Mutex<Published>>,
    events: EventSink,
) {
    loop {
        match jobs.recv_timeout(Duration::from_millis(250)) {
            Ok(Job::Plan(task, reply)) => {
                let r = task.plan(&mut session).map_err(|e| format!("{e:#}"));
                let _ = reply.send(r);
            }
            Ok(Job::Run(task, control)) => {
                run_one(
                    &mut session,
                    &task,
                    &control,
                    &runs_dir,
                    &published,
                    &events,
                );
            }
            Err(RecvTimeoutError::Timeout) => {
                // Idle: look, so the page follows a table that changes by hand.
                if let Err(e) = session.live.look() {
                    tracing::debug!("idle look: {e:#}");
                }
            }
            Err(RecvTimeoutError::Disconnected) => return,
        }
    }
}

fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
}

fn run_one(
    session: &mut Session,
    task: &Task,
    control: &Control,
    runs_dir: &std::path::Path,
    published: &Mutex<Published>,
    events: &EventSink,
) {
    let dir = runs_dir.join(
        crate::task::folder::default_folder(task.name())
            .file_name()
            .map_or_else(|| task.name().into(), |n| n.to_os_string()),
    );
    let dir = unique(dir);
    let name = dir
        .file_name()
        .map_or(String::new(), |n| n.to_string_lossy().into_owned());
    lock(published).running = Some((task.name().into(), task.summary()));
    let folder = match RunFolder::create(&dir) {
        Ok(f) => Arc::new(f),
        Err(e) => {
            events(&TaskEvent::Done {
                success: false,
                message: format!("could not create the run folder: {e:#}"),
            });
            lock(published).running = None;
            return;
        }
    };
    session.live.record_into(Some(folder.recording()));
    let log = Arc::clone(&folder);
    let outer = events.clone();
    let sink: EventSink = Arc::new(move |e: &TaskEvent| {
        log.event(e);
        outer(e);
    });
    let outcome = task.run(session, control, &sink);
    session.live.record_into(None);
    drop(sink);
    let message = match Arc::try_unwrap(folder) {
        Ok(f) => match f.finish(&session.scene, task.name(), &outcome) {
            Ok(_) => outcome.message.clone(),
            Err(e) => format!("{} (writing its folder failed: {e:#})", outcome.message),
        },
        Err(_) => outcome.message.clone(),
    };
    let mut p = lock(published);
    p.running = None;
    p.runs.push(RunInfo {
        name,
        task: task.name().into(),
        success: outcome.success,
        message,
    });
}

/// `dir`, or `dir-2`, `dir-3` … when it is taken.
fn unique(dir: PathBuf) -> PathBuf {
    if !dir.exists() {
        return dir;
    }
    (2..)
        .map(|k| PathBuf::from(format!("{}-{k}", dir.display())))
        .find(|d| !d.exists())
        .unwrap_or(dir)
}
