//! `harness review` in a real browser: after a change to the arrow scene's light and a failing
//! check, the served page's Accept button on the light buffer (gl), with a reason typed once for
//! the page, blesses what the check kept and records the reason, the page marks that row
//! accepted, and the next check passes the light buffer and still fails the final image; the
//! scene's Accept then takes the rest, and golden/ ends exactly as `harness bless --scene arrow
//! --reason` (the same words) leaves it from the same change (the blessing times aside). The
//! server runs with rendering forbidden (`HARNESS_NO_RENDER`, which its children inherit): it
//! accepts on the checks' own verification and renders nothing. Requests without the page's
//! token, naming another host, or with a key it does not know, are refused.
//!
//! Needs Chromium, like `report` (skipped with a note without it, unless REQUIRE_CHROMIUM=1).

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;

use serde_json::json;

use super::report::{check_after_a_light_change, chromium, workspace_with_a_light_change, Browser};
use crate::common;

/// Sends a raw HTTP request to 127.0.0.1:`port`: its status code and body.
fn send(port: u16, request: &str) -> (u16, String) {
    let mut stream = TcpStream::connect(("127.0.0.1", port)).unwrap();
    stream.write_all(request.as_bytes()).unwrap();
    // Bytes first: a PNG served is no UTF-8 (read_to_string would keep nothing of it).
    let mut bytes = Vec::new();
    let _ = stream.read_to_end(&mut bytes);
    let answer = String::from_utf8_lossy(&bytes).into_owned();
    let code = answer
        .split_whitespace()
        .nth(1)
        .and_then(|code| code.parse().ok())
        .unwrap_or_else(|| panic!("no status in {answer:?}"));
    let body = answer.split_once("\r\n\r\n").map(|(_, b)| b.to_owned());
    (code, body.unwrap_or_default())
}

/// Sends a raw HTTP request to 127.0.0.1:`port` and returns its status code.
fn status(port: u16, request: &str) -> u16 {
    send(port, request).0
}

/// A `harness review` server, killed when the test ends, however it ends; holds its stdout
/// open until then (a closed pipe would end it at its next line).
pub(crate) struct Server {
    child: std::process::Child,
    _stdout: BufReader<std::process::ChildStdout>,
    /// The page's address, token included.
    pub url: String,
    /// Its port.
    pub port: u16,
    /// The page's token.
    pub token: String,
}

impl Server {
    /// Serves the check kept under `out` of the workspace at `root`, rendering forbidden.
    pub(crate) fn start(root: &std::path::Path, out: &std::path::Path) -> Self {
        let mut child = common::harness_command()
            .args(["review", "--out"])
            .arg(out)
            .env("HARNESS_ROOT", root)
            .env(harness::faults::NO_RENDER, "1")
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::null())
            .spawn()
            .unwrap();
        let mut first = String::new();
        let mut stdout = BufReader::new(child.stdout.take().unwrap());
        stdout.read_line(&mut first).unwrap();
        let url = first
            .split_whitespace()
            .find(|w| w.starts_with("http://127.0.0.1:"))
            .unwrap_or_else(|| panic!("no address in {first:?}"))
            .to_owned();
        let port: u16 = url["http://127.0.0.1:".len()..]
            .split('/')
            .next()
            .unwrap()
            .parse()
            .unwrap();
        let token = url.split("token=").nth(1).unwrap().to_owned();
        Server {
            child,
            _stdout: stdout,
            url,
            port,
            token,
        }
    }

    /// Posts `body` to /accept as the page does; the answer's JSON.
    pub(crate) fn accept(&self, body: &serde_json::Value) -> serde_json::Value {
        let body = body.to_string();
        let request = format!(
            "POST /accept HTTP/1.1\r\nHost: 127.0.0.1:{}\r\nX-Harness-Token: {}\r\n\
             Content-Type: application/json\r\nContent-Length: {}\r\nConnection: close\r\n\r\n{body}",
            self.port,
            self.token,
            body.len()
        );
        let (code, answer) = send(self.port, &request);
        assert_eq!(code, 200, "{answer}");
        serde_json::from_str(&answer).unwrap()
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

#[test]
fn accepting_a_pass_on_the_review_page_blesses_what_the_check_kept() {
    let Some(executable) = chromium() else {
        if std::env::var("REQUIRE_CHROMIUM").as_deref() == Ok("1") {
            panic!("REQUIRE_CHROMIUM=1 but no Chromium found (apt-get install -y chromium)");
        }
        eprintln!("note: no Chromium; review server test skipped (apt-get install -y chromium)");
        return;
    };
    if !common::gl_available() {
        return;
    }
    let (root, out) = check_after_a_light_change(true);
    // The check verified what it kept, and the page says so.
    let page = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(
        page.contains("<p class=\"verified\" data-scene=\"arrow\">arrow's new light, final (gl)"),
        "the page does not say the check verified arrow's outputs"
    );
    // The same change blessed the usual way, in a second workspace.
    let blessed_root = workspace_with_a_light_change();
    let reason = "arrow's light brightened on purpose";
    let output = common::harness_command()
        .args([
            "bless",
            "--scene",
            "arrow",
            "--no-speed",
            "--reason",
            reason,
        ])
        .env("HARNESS_ROOT", blessed_root.path())
        .output()
        .unwrap();
    assert!(output.status.success(), "{output:?}");
    // The check verified these candidates already: the bless (which holds the scene's lock
    // while it verifies) finds them kept, and renders nothing under the sources again. (Where
    // no verification can be kept, no Mesa driver being mapped to key it by, none is.)
    let kept_any = std::fs::read_dir(common::verify_cache())
        .into_iter()
        .flatten()
        .flatten()
        .any(|entry| entry.path().extension().is_some_and(|e| e == "json"));
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        !kept_any || stderr.contains("every source: the same candidates were verified before"),
        "{stderr}"
    );
    let server = Server::start(root.path(), &out);
    let (url, port, token) = (server.url.clone(), server.port, server.token.clone());
    refuses_what_the_page_would_not_send(port, &token);
    serves_the_files_the_page_links(port, &out);

    let mut browser = Browser::launch(executable);
    browser.open(&url);
    let row = "table.summary tr.failed[data-scene=arrow][data-pass=light][data-backend=gl]";
    assert_eq!(
        browser.eval(&format!(
            "document.querySelectorAll('{row} button.accept').length"
        )),
        json!(1)
    );
    // The reviewer says why, once for the page; each Accept sends it.
    browser.eval(&format!(
        "document.querySelector('.accept-bar input.accept-reason').value = {}",
        json!(reason)
    ));
    browser.click_on(&format!("{row} button.accept"));
    let marked = browser.eval(&wait_for(
        &format!("document.querySelector('{row}')"),
        "r.classList.contains('accepted')",
        "r.querySelector('td.result').textContent",
    ));
    assert_eq!(marked, json!("ACCEPTED"));
    // Accepting it again is refused as done, not as a golden changed by someone else.
    let again = server.accept(&json!({ "scene": "arrow", "pass": "light", "backend": "gl" }));
    assert!(
        again["refused"].to_string().contains("already accepted"),
        "{again}"
    );

    let check = || {
        let output = common::harness_command()
            .args(["check", "--no-speed", "--scene", "arrow", "--backend", "gl"])
            .args(["--json", "--out"])
            .arg(&out)
            .env("HARNESS_ROOT", root.path())
            .output()
            .unwrap();
        common::cli::failing_passes(&output.stdout)
    };
    assert_eq!(check(), ["final"]);
    let golden = root.path().join("golden");
    let record = &harness::golden::GoldenStore::new(&golden)
        .records("arrow")
        .unwrap()["light"];
    assert!(!record.unverified && record.previous.starts_with("CHANGED vs old golden"));
    assert_eq!(record.reason.as_deref(), Some(reason));

    // The scene's Accept (the page is the first check's; the server accepts from the last).
    let scene = ".accept-bar button.accept-scene[data-scene=arrow]";
    browser.click_on(scene);
    let answer = browser.eval(&wait_for(
        &format!("document.querySelector('{scene}')"),
        "r.textContent !== 'accepting…'",
        "r.textContent + ' ' + r.title",
    ));
    assert_eq!(answer, json!("accepted "));
    drop(server);
    assert!(check().is_empty());
    let without_times = |root: &std::path::Path| {
        let files = crate::cli_bless::snapshot(&root.join("golden/arrow"));
        files
            .into_iter()
            .map(|(path, (bytes, _))| {
                let name = path.file_name().unwrap().to_string_lossy().into_owned();
                let bytes = if name == "blessed.toml" {
                    String::from_utf8(bytes)
                        .unwrap()
                        .lines()
                        .filter(|l| !l.starts_with("blessed = "))
                        .collect::<Vec<_>>()
                        .join("\n")
                        .into_bytes()
                } else {
                    bytes
                };
                (name, bytes)
            })
            .collect::<std::collections::BTreeMap<_, _>>()
    };
    let accepted = without_times(root.path());
    let blessed = without_times(blessed_root.path());
    assert_eq!(
        accepted.keys().collect::<Vec<_>>(),
        blessed.keys().collect::<Vec<_>>()
    );
    for (name, bytes) in &accepted {
        assert!(
            *bytes == blessed[name],
            "golden/arrow/{name} differs from what `bless --scene arrow` writes"
        );
    }
}

/// The server refuses an accept without the page's token, with a wrong one, for another host
/// or origin, the page itself without its token, and a request with a key it does not know (a
/// misspelt filter is a bad request, not an empty one that would accept the whole run).
fn refuses_what_the_page_would_not_send(port: u16, token: &str) {
    let host = format!("Host: 127.0.0.1:{port}\r\n");
    let post = |headers: &str| {
        format!(
            "POST /accept HTTP/1.1\r\n{headers}Content-Type: application/json\r\n\
             Content-Length: 2\r\nConnection: close\r\n\r\n{{}}"
        )
    };

    // Refused: no token, a wrong one, another host, another origin, the page without its token.
    assert_eq!(status(port, &post(&host)), 403);
    assert_eq!(
        status(port, &post(&format!("{host}X-Harness-Token: 00\r\n"))),
        403
    );
    let token_header = format!("X-Harness-Token: {token}\r\n");
    let elsewhere = format!("Host: attacker.example:{port}\r\n{token_header}");
    assert_eq!(status(port, &post(&elsewhere)), 403);
    let origin = format!("{host}{token_header}Origin: http://attacker.example\r\n");
    assert_eq!(status(port, &post(&origin)), 403);
    let page = format!("GET / HTTP/1.1\r\n{host}Connection: close\r\n\r\n");
    assert_eq!(status(port, &page), 403);
    // A misspelt key is a bad request, not an empty filter (which would accept the whole run).
    let misspelt = r#"{"scen":"arrow"}"#;
    let (code, answer) = send(
        port,
        &format!(
            "POST /accept HTTP/1.1\r\n{host}{token_header}Content-Type: application/json\r\n\
             Content-Length: {}\r\nConnection: close\r\n\r\n{misspelt}",
            misspelt.len()
        ),
    );
    assert_eq!(code, 400, "{answer}");
    assert!(answer.contains("unknown field `scen`"), "{answer}");
}

/// The page's links to the check's failure images resolve on the server (they carry no token);
/// nothing outside `failures/` does, however the path is spelt.
fn serves_the_files_the_page_links(port: u16, out: &std::path::Path) {
    let get = |path: &str| {
        send(
            port,
            &format!("GET {path} HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nConnection: close\r\n\r\n"),
        )
    };
    let page = std::fs::read_to_string(out.join("report.html")).unwrap();
    let linked: Vec<&str> = page
        .split("href=\"")
        .skip(1)
        .filter_map(|rest| rest.split('"').next())
        .filter(|link| link.starts_with("failures/"))
        .collect();
    assert!(linked.iter().any(|l| l.ends_with(".png")), "{linked:?}");
    for link in linked {
        let (code, answer) = get(&format!("/{link}"));
        assert_eq!(code, 200, "{link}: {answer}");
        if link.ends_with(".png") {
            assert!(answer.contains("PNG\r\n"), "{link}");
        }
    }
    for outside in [
        "/failures/../last-check.json",
        "/failures/%2e%2e/last-check.json",
        "/failures/arrow/../../report.html",
        "/failures/",
        "/last-check.json",
    ] {
        assert_eq!(get(outside).0, 404, "{outside}");
    }
}

/// A CDP expression that waits (up to 2 minutes) until `done` holds of `r` (the element
/// `element` finds), then gives `value` of it, or what the element shows if it never does.
pub(crate) fn wait_for(element: &str, done: &str, value: &str) -> String {
    format!(
        "new Promise((resolve) => {{ const start = Date.now(); const poll = () => {{ \
         const r = {element}; \
         if ({done}) resolve({value}); \
         else if (Date.now() - start > 120000) resolve('timed out: ' + r.outerHTML); \
         else setTimeout(poll, 100); }}; poll(); }})"
    )
}
