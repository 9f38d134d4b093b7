//! `harness review`: the last check's review page served on 127.0.0.1, with Accept buttons on
//! each failing pass, each scene and the whole run. Accepting blesses exactly the outputs that
//! `check` rendered and kept ([`crate::golden::accept`]), verified and recorded as any bless
//! ([`crate::golden::verify`]); it never renders the check again. A failing speed row's Accept
//! records the ratio the check measured as that pass's timing golden; a scene's or the run's
//! Accept records every such ratio of theirs.
//! The page marks what was accepted; a later `check` shows it passing.
//!
//! The server answers only its own page: every request must name it in its Host header
//! (`127.0.0.1:<port>` or `localhost:<port>`: a page elsewhere that makes the browser call it, or
//! a DNS name rebound to 127.0.0.1, names another), and every accept must carry the run's
//! random token (printed in the URL, sent back in a header) and, when the browser says where it
//! comes from, an Origin of the same host.

use std::collections::BTreeSet;
use std::io::Read;
use std::path::{Path, PathBuf};

use engine::backend::BackendKind;

use crate::golden::accept::{self, Candidate};
use crate::golden::suite::{self, Case};
use crate::golden::GoldenStore;

/// The script the served page gets: the Accept buttons and what they do.
const SCRIPT: &str = include_str!("accept.js");

/// Why the review server could not run.
#[derive(Debug, thiserror::Error)]
pub enum ReviewError {
    /// No page to serve.
    #[error("no review page at {0}: run `harness check` first")]
    NoPage(PathBuf),
    /// The address could not be bound.
    #[error("cannot listen on 127.0.0.1:{port}: {message}")]
    Bind {
        /// The port asked for.
        port: u16,
        /// Why.
        message: String,
    },
    /// No random token could be made.
    #[error("cannot read random bytes for the page's token: {0}")]
    Token(std::io::Error),
}

/// What one accept request asks for: a pass on a backend, a scene, or (all empty) the run.
#[derive(Clone, Debug, Default, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AcceptRequest {
    /// Only this scene.
    pub scene: Option<String>,
    /// Only this pass (with a scene).
    pub pass: Option<String>,
    /// The backend whose outputs to accept (the reference backend by default).
    pub backend: Option<BackendKind>,
    /// A speed check's row: the pass is a plan pass, and its timing golden is accepted (on the
    /// backend given, or every backend).
    #[serde(default)]
    pub speed: bool,
    /// Why the pictures or timings changed, as the reviewer typed it: recorded beside each
    /// golden written, as `harness bless --reason` does.
    #[serde(default)]
    pub reason: Option<String>,
}

/// The answer to an accept request.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct AcceptAnswer {
    /// `(scene, pass, backend)` accepted and written.
    pub accepted: Vec<(String, String, BackendKind)>,
    /// Those refused, with why.
    pub refused: Vec<(String, String, String)>,
    /// A line per timing golden written, as `bless --from-last-check` prints it: how it was
    /// written and, on a recorded host, which recording that made stale and how to record the
    /// host again.
    pub notes: Vec<String>,
}

/// The server of one review.
pub struct Review {
    server: tiny_http::Server,
    port: u16,
    token: String,
    out: PathBuf,
    /// `(scene, pass, backend)` accepted so far (the page marks them again after a reload).
    accepted: BTreeSet<(String, String, BackendKind)>,
}

impl Review {
    /// Binds 127.0.0.1:`port` (0: any free port) for the check kept under `out`.
    pub fn bind(out: &Path, port: u16) -> Result<Self, ReviewError> {
        if !out.join("report.html").exists() || !out.join(accept::LAST_CHECK).exists() {
            return Err(ReviewError::NoPage(out.join("report.html")));
        }
        let server =
            tiny_http::Server::http(("127.0.0.1", port)).map_err(|e| ReviewError::Bind {
                port,
                message: e.to_string(),
            })?;
        let port = server
            .server_addr()
            .to_ip()
            .map(|a| a.port())
            .unwrap_or(port);
        Ok(Self {
            server,
            port,
            token: token().map_err(ReviewError::Token)?,
            out: out.to_owned(),
            accepted: BTreeSet::new(),
        })
    }

    /// The page's address, token included.
    pub fn url(&self) -> String {
        format!("http://127.0.0.1:{}/?token={}", self.port, self.token)
    }

    /// Answers requests until the process ends.
    pub fn serve(mut self, store: &GoldenStore) {
        while let Ok(request) = self.server.recv() {
            self.answer(request, store);
        }
    }

    fn answer(&mut self, mut request: tiny_http::Request, store: &GoldenStore) {
        let header = |name: &str| {
            request
                .headers()
                .iter()
                .find(|h| h.field.as_str().as_str().eq_ignore_ascii_case(name))
                .map(|h| h.value.as_str().to_owned())
        };
        let host_ok = header("Host").is_some_and(|host| {
            host == format!("127.0.0.1:{}", self.port) || host == format!("localhost:{}", self.port)
        });
        let origin_ok = header("Origin").is_none_or(|origin| {
            origin == format!("http://127.0.0.1:{}", self.port)
                || origin == format!("http://localhost:{}", self.port)
        });
        let url = request.url().to_owned();
        let (path, query) = url.split_once('?').unwrap_or((&url, ""));
        let forbidden = |why: &str| {
            tiny_http::Response::from_string(format!("refused: {why}\n")).with_status_code(403)
        };
        if !host_ok || !origin_ok {
            let _ = request.respond(forbidden("this server answers only its own page"));
            return;
        }
        let method = request.method().clone();
        let response = match (method, path) {
            (tiny_http::Method::Get, "/") => {
                let token_ok = query
                    .split('&')
                    .any(|kv| kv == format!("token={}", self.token));
                if token_ok {
                    self.page()
                } else {
                    forbidden("no or wrong token (use the URL `harness review` printed)").boxed()
                }
            }
            (tiny_http::Method::Post, "/accept") => {
                if header("X-Harness-Token").as_deref() != Some(self.token.as_str()) {
                    forbidden("no or wrong token").boxed()
                } else {
                    let mut body = String::new();
                    let _ = request
                        .as_reader()
                        .take(64 * 1024)
                        .read_to_string(&mut body);
                    match serde_json::from_str::<AcceptRequest>(&body) {
                        Ok(ask) => {
                            let answer = self.accept(&ask, store);
                            json(&answer)
                        }
                        Err(e) => tiny_http::Response::from_string(format!("bad request: {e}\n"))
                            .with_status_code(400)
                            .boxed(),
                    }
                }
            }
            (tiny_http::Method::Get, path) if path.starts_with("/failures/") => {
                self.failure_file(path)
            }
            _ => not_found(),
        };
        let _ = request.respond(response);
    }

    /// A file the page links under `failures/` (the check's kept outputs, goldens and
    /// differences), read from the check's folder; anything outside it is not found. Served
    /// without the token, as the page's links carry none: they are this machine's render
    /// outputs, on its disk; the Host check refuses a request naming another host (a rebound
    /// name), though another site's page could still show one as an image it cannot read.
    fn failure_file(&self, url_path: &str) -> tiny_http::ResponseBox {
        let Some(relative) = crate::url::decoded(url_path.trim_start_matches('/')) else {
            return not_found();
        };
        let relative = std::path::Path::new(&relative);
        let plain = relative
            .components()
            .all(|c| matches!(c, std::path::Component::Normal(_)));
        let root = self.out.join("failures");
        let file = self.out.join(relative);
        let inside = match (file.canonicalize(), root.canonicalize()) {
            (Ok(file), Ok(root)) => file.starts_with(root) && file.is_file(),
            _ => false,
        };
        if !plain || !inside {
            return not_found();
        }
        let Ok(bytes) = std::fs::read(&file) else {
            return not_found();
        };
        let kind = if file.extension().is_some_and(|x| x == "png") {
            "image/png"
        } else {
            "application/octet-stream"
        };
        let mut response = tiny_http::Response::from_data(bytes);
        if let Ok(header) = tiny_http::Header::from_bytes("Content-Type", kind) {
            response.add_header(header);
        }
        response.boxed()
    }

    /// The review page with the token, what was accepted, and the Accept script.
    fn page(&self) -> tiny_http::ResponseBox {
        let html = match std::fs::read_to_string(self.out.join("report.html")) {
            Ok(html) => html,
            Err(e) => {
                return tiny_http::Response::from_string(format!("cannot read the page: {e}\n"))
                    .with_status_code(500)
                    .boxed()
            }
        };
        let state = serde_json::json!({
            "token": self.token,
            "accepted": self.accepted.iter().collect::<Vec<_>>(),
        });
        let inject = format!("<script>window.HARNESS_REVIEW = {state};\n{SCRIPT}</script></body>");
        let page = html.replacen("</body>", &inject, 1);
        let mut response = tiny_http::Response::from_string(page);
        if let Ok(header) =
            tiny_http::Header::from_bytes("Content-Type", "text/html; charset=utf-8")
        {
            response.add_header(header);
        }
        response.boxed()
    }

    /// Accepts what `ask` names from the last check: verified, then blessed, scene by scene.
    fn accept(&mut self, ask: &AcceptRequest, store: &GoldenStore) -> AcceptAnswer {
        let mut answer = AcceptAnswer::default();
        let reason = ask
            .reason
            .as_deref()
            .and_then(crate::golden::bless::given_reason);
        let options = accept::AcceptOptions {
            reason,
            check_out: Some(&self.out),
            ..Default::default()
        };
        if ask.speed {
            let scenes: Vec<String> = ask.scene.iter().cloned().collect();
            let passes: Vec<String> = ask.pass.iter().cloned().collect();
            self.accept_timings(&scenes, &passes, ask.backend, reason, store, &mut answer);
            if answer.accepted.is_empty() && answer.refused.is_empty() {
                let what = format!("{} {}", scenes.join(","), passes.join(","));
                answer.refused.push((
                    what,
                    "speed".into(),
                    "the last check has no speed check beyond its limit there".into(),
                ));
            }
            return answer;
        }
        let scenes: Vec<String> = ask.scene.iter().cloned().collect();
        let passes: Vec<String> = ask.pass.iter().cloned().collect();
        let candidates = match accept::candidates(&self.out, ask.backend, &scenes, &passes) {
            Ok(candidates) => candidates,
            Err(e) => {
                answer.refused.push(("-".into(), "-".into(), e.to_string()));
                return answer;
            }
        };
        let mut arguments: Vec<String> = Vec::new();
        for c in &candidates {
            if !arguments.contains(&c.check.scene_argument) {
                arguments.push(c.check.scene_argument.clone());
            }
        }
        for argument in arguments {
            let mine: Vec<&Candidate> = candidates
                .iter()
                .filter(|c| c.check.scene_argument == argument)
                .collect();
            let refuse = |answer: &mut AcceptAnswer, why: String| {
                for c in &mine {
                    let (scene, pass) = (c.check.scene.clone(), c.check.pass.to_string());
                    answer.refused.push((scene, pass, why.clone()));
                }
            };
            let case = match Case::load(&argument) {
                Ok(case) => case,
                Err(e) => {
                    refuse(&mut answer, e.to_string());
                    continue;
                }
            };
            let lock = match store.lock_scene(case.name(), |_| {}) {
                Ok(lock) => lock,
                Err(e) => {
                    refuse(&mut answer, e.to_string());
                    continue;
                }
            };
            let exe = std::env::current_exe().map_err(|e| e.to_string());
            let done = exe.and_then(|exe| {
                accept::accept_scene(&exe, store, &lock, &case, &mine, options, |_| {})
            });
            match done {
                Ok(done) if !done.disagreements.is_empty() => {
                    refuse(
                        &mut answer,
                        format!("not verified: {}", done.disagreements[0]),
                    );
                }
                Ok(done) => {
                    for blessed in done.accepted {
                        let pass = blessed.pass.to_string();
                        // The candidates' backend: the one asked for, or the check's reference.
                        let backend = mine.first().map(|c| c.check.backend);
                        let backend = backend.unwrap_or(suite::REFERENCE_BACKEND);
                        let key = (case.name().to_owned(), pass.clone(), backend);
                        self.accepted.insert(key);
                        answer
                            .accepted
                            .push((case.name().to_owned(), pass, backend));
                    }
                    for (pass, why) in done.refused {
                        answer
                            .refused
                            .push((case.name().to_owned(), pass.to_string(), why));
                    }
                }
                Err(why) => refuse(&mut answer, why),
            }
        }
        // A scene's or the run's Accept takes its timing goldens too, as the check measured.
        // A speed row it cannot take (another host's timing goldens) is no refusal of the
        // images beside it, unless nothing was accepted; a failure to accept is one always.
        if ask.pass.is_none() {
            let mut timings = AcceptAnswer::default();
            self.accept_timings(&scenes, &[], None, reason, store, &mut timings);
            answer.accepted.extend(timings.accepted);
            answer.notes.extend(timings.notes);
            let nothing = answer.accepted.is_empty();
            answer.refused.extend(
                timings
                    .refused
                    .into_iter()
                    .filter(|(_, pass, _)| nothing || pass == "speed"),
            );
        }
        answer
    }

    /// Accepts the last check's speed checks beyond their limits of `scenes` and `passes` (plan
    /// passes; all when empty), on `backend` (every one when None), with `reason` beside each.
    fn accept_timings(
        &mut self,
        scenes: &[String],
        passes: &[String],
        backend: Option<BackendKind>,
        reason: Option<&str>,
        store: &GoldenStore,
        answer: &mut AcceptAnswer,
    ) {
        let (checks, checked) = match accept::speed_candidates(&self.out, scenes, passes) {
            Ok((checks, checked)) => (
                checks
                    .into_iter()
                    .filter(|c| backend.is_none_or(|b| c.backend == b))
                    .collect::<Vec<_>>(),
                checked,
            ),
            Err(e) => {
                answer
                    .refused
                    .push(("-".into(), "speed".into(), e.to_string()));
                return;
            }
        };
        for (scene, result) in
            accept::accept_all_timings(store, &checks, &checked, false, reason, |_| {})
        {
            match result {
                Ok(done) => {
                    answer.notes.extend(done.written.iter().cloned());
                    // Each check is written, or kept out with why.
                    for c in checks.iter().filter(|c| c.scene == scene) {
                        let pass = format!("speed {}", c.pass);
                        let kept = done
                            .kept
                            .iter()
                            .find(|k| k.pass == c.pass && k.backend == c.backend);
                        if let Some(kept) = kept {
                            answer.refused.push((scene.clone(), pass, kept.why.clone()));
                        } else {
                            self.accepted
                                .insert((scene.clone(), pass.clone(), c.backend));
                            answer.accepted.push((scene.clone(), pass, c.backend));
                        }
                    }
                }
                Err(why) => answer.refused.push((scene, "speed".into(), why)),
            }
        }
    }
}

/// `value` as a JSON response.
fn json(value: &impl serde::Serialize) -> tiny_http::ResponseBox {
    let text = serde_json::to_string(value).unwrap_or_else(|_| "{}".to_owned());
    let mut response = tiny_http::Response::from_string(text);
    if let Ok(header) = tiny_http::Header::from_bytes("Content-Type", "application/json") {
        response.add_header(header);
    }
    response.boxed()
}

/// 128 random bits as hex, from the operating system.
fn token() -> std::io::Result<String> {
    let mut bytes = [0u8; 16];
    std::fs::File::open("/dev/urandom")?.read_exact(&mut bytes)?;
    Ok(bytes.iter().map(|b| format!("{b:02x}")).collect())
}

/// The answer to what the server does not serve.
fn not_found() -> tiny_http::ResponseBox {
    tiny_http::Response::from_string("not found\n")
        .with_status_code(404)
        .boxed()
}
