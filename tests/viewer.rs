//! The step viewer page in a real browser: a fixture is built with
//! `--formats html`, and headless Chromium (Debian's `chromium`, WebGL
//! through SwiftShader, every host name unresolvable) opens the page at the
//! first and the last step. The page must come up (`data-state="ready"` at
//! the step the URL asks for), log nothing to the console, and draw the
//! model: the two screenshots show it, with the current step outlined, and
//! differ. The page itself must name no URL.
//!
//! Firefox (Debian's `firefox-esr`) opens the page too, at the first and
//! the last step: in a real window on a virtual X server (`Xvfb`, WebGL
//! through Mesa's llvmpipe; headless Firefox offers no WebGL), inside a
//! frame of a small page that waits for the viewer's ready state and logs
//! it to standard output; ImageMagick's `import` takes the screenshot.
//!
//! Chromium, Firefox, Xvfb and ImageMagick are outside tools (see
//! `tests/common`): without one, the test that needs it skips outside CI
//! and fails under CI (`.ci/run tools` installs them).

use crate::common;

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc;
use std::time::Duration;

use brickwright::pipeline::{self, BuildOptions, Formats, Silent, Stability};
use brickwright::voxel::Sizing;

/// Builds `fixture` at `studs` with only the viewer page; its path and
/// the step count.
fn build_page(fixture: &str, studs: u32, out: &Path) -> (PathBuf, u32) {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let mut opts = BuildOptions::new(root.join("fixtures").join(fixture));
    opts.out_dir = out.to_path_buf();
    opts.sizing = Sizing::Studs(studs);
    opts.stability = Stability::Off;
    opts.formats = Formats::parse("html").unwrap();
    let built = pipeline::build(&opts, &Silent).unwrap_or_else(|e| panic!("{fixture}: {e}"));
    let stem = fixture.rsplit_once('.').map_or(fixture, |(s, _)| s);
    let page = out.join(format!("{stem}.html"));
    assert!(
        built.report.outputs.contains(&page.display().to_string()),
        "{:?}",
        built.report.outputs
    );
    (page, built.report.steps)
}

/// Headless Chromium on `url` with `args` added; its standard output and
/// the page's console lines (from its log on standard error).
fn chromium(profile: &Path, url: &str, args: &[&str]) -> (String, Vec<String>) {
    // Software WebGL's start-up runs on real time, not the virtual time
    // budget: a DOM dumped while the page still says `loading` is taken
    // again (up to three times) rather than failed.
    let mut tries = 0;
    loop {
        let (dom, console) = chromium_once(profile, url, args);
        tries += 1;
        if tries >= 3 || body_attr(&dom, "data-state").as_deref() != Some("loading") {
            return (dom, console);
        }
    }
}

/// One browser at a time: three software-rendering browsers at once on
/// two cores can miss the page's ready state within the time budget.
static ONE_BROWSER: std::sync::Mutex<()> = std::sync::Mutex::new(());

fn chromium_once(profile: &Path, url: &str, args: &[&str]) -> (String, Vec<String>) {
    let _turn = ONE_BROWSER.lock().unwrap_or_else(|e| e.into_inner());
    let out = Command::new("chromium")
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--use-gl=swiftshader",
            "--enable-unsafe-swiftshader",
            "--hide-scrollbars",
            "--no-first-run",
            "--disable-extensions",
            "--disable-background-networking",
            // Nothing can come from the network.
            "--host-resolver-rules=MAP * ~NOTFOUND",
            "--window-size=1000,750",
            "--virtual-time-budget=8000",
            "--enable-logging=stderr",
            "--v=0",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .args(args)
        .arg(url)
        .output()
        .expect("chromium runs");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "chromium failed on {url}: {stderr}");
    let console = stderr
        .lines()
        .filter(|l| l.contains(":CONSOLE"))
        // Chromium's own note when it reads the frame back for a
        // screenshot, not the page's.
        .filter(|l| !l.contains("GPU stall due to ReadPixels"))
        .map(str::to_string)
        .collect();
    (String::from_utf8_lossy(&out.stdout).into_owned(), console)
}

/// The value of `attr` on the `<body>` tag of a dumped DOM.
fn body_attr(dom: &str, attr: &str) -> Option<String> {
    let tag = &dom[dom.find("<body")?..];
    let tag = &tag[..tag.find('>')?];
    let key = format!("{attr}=\"");
    let start = tag.find(&key)? + key.len();
    Some(tag[start..].split('"').next()?.to_string())
}

/// Pixels of the 3D view (the page's left part) in an RGB screenshot
/// whose top left 1000x750 pixels show the page.
fn view_pixels(png: &Path) -> Vec<[u8; 3]> {
    let img = image::open(png)
        .unwrap_or_else(|e| panic!("{}: {e}", png.display()))
        .to_rgb8();
    let (w, h) = img.dimensions();
    assert!(w >= 1000 && h >= 750, "{}: {w}x{h}", png.display());
    let mut px = Vec::new();
    for y in 0..560 {
        for x in 0..600 {
            px.push(img.get_pixel(x, y).0);
        }
    }
    px
}

fn far(a: [u8; 3], b: [u8; 3], by: i32) -> bool {
    (0..3).any(|k| (i32::from(a[k]) - i32::from(b[k])).abs() > by)
}

#[test]
fn chromium_shows_the_first_and_the_last_step() {
    let tmp = tempfile::tempdir().unwrap();
    let (page, steps) = build_page("house.obj", 10, tmp.path());
    assert!(steps >= 3, "{steps} steps");
    let html = std::fs::read_to_string(&page).unwrap();
    for needle in ["://", "src=", "href=", "url(", "@import"] {
        assert!(!html.contains(needle), "the page holds `{needle}`");
    }
    if !common::required_tool("chromium", "chromium", "--version") {
        return;
    }
    let profile = tmp.path().join("profile");
    let mut shots = Vec::new();
    for step in [1, steps] {
        let url = format!("file://{}#step={step}", page.display());
        let (dom, console) = chromium(&profile, &url, &["--dump-dom"]);
        assert_eq!(
            body_attr(&dom, "data-state").as_deref(),
            Some("ready"),
            "{url}"
        );
        assert_eq!(
            body_attr(&dom, "data-step"),
            Some(step.to_string()),
            "{url}"
        );
        assert!(console.is_empty(), "{url}: the console says {console:#?}");

        let png = tmp.path().join(format!("step-{step}.png"));
        let shot = format!("--screenshot={}", png.display());
        let (_, console) = chromium(&profile, &url, &[&shot]);
        assert!(console.is_empty(), "{url}: the console says {console:#?}");
        shots.push(shows_the_model(&png, step, "chromium"));
    }
    first_and_last_differ(&shots);
}

/// The model's pixels in the view of screenshot `png` at `step`, after
/// checking that the model and the current step's outline show; kept in
/// `$VIEWER_SHOTS` when set.
fn shows_the_model(png: &Path, step: u32, browser: &str) -> (usize, Vec<[u8; 3]>) {
    let background = [0xee, 0xf0, 0xf3];
    let highlight = [0xff, 0x9e, 0x00];
    if let Some(keep) = std::env::var_os("VIEWER_SHOTS") {
        let keep = PathBuf::from(keep);
        std::fs::create_dir_all(&keep).unwrap();
        std::fs::copy(png, keep.join(format!("{browser}-step-{step}.png"))).unwrap();
    }
    let px = view_pixels(png);
    let model = px.iter().filter(|&&p| far(p, background, 24)).count();
    let outlined = px.iter().filter(|&&p| !far(p, highlight, 40)).count();
    assert!(
        model * 50 > px.len(),
        "{browser}, step {step}: {model} model pixels"
    );
    assert!(
        outlined > 100,
        "{browser}, step {step}: {outlined} highlight pixels"
    );
    (model, px)
}

/// The finished model covers more of the view than the first step, and
/// the two views differ.
fn first_and_last_differ(shots: &[(usize, Vec<[u8; 3]>)]) {
    let (first, last) = (&shots[0], &shots[1]);
    assert!(
        last.0 > first.0,
        "the finished model covers more of the view"
    );
    let changed = first
        .1
        .iter()
        .zip(&last.1)
        .filter(|(a, b)| far(**a, **b, 24))
        .count();
    assert!(changed * 20 > first.1.len(), "{changed} pixels differ");
}

#[test]
fn the_url_chooses_the_step_and_the_exploded_view() {
    let tmp = tempfile::tempdir().unwrap();
    let (page, steps) = build_page("wedge.stl", 8, tmp.path());
    if !common::required_tool("chromium", "chromium", "--version") {
        return;
    }
    let profile = tmp.path().join("profile");
    for (hash, want, exploded) in [
        ("#step=9999", steps, "0"),
        ("#step=0", 1, "0"),
        ("#other", 1, "0"),
        ("#step=2&exploded=1", 2, "1"),
    ] {
        let url = format!("file://{}{hash}", page.display());
        let (dom, console) = chromium(&profile, &url, &["--dump-dom"]);
        assert_eq!(
            body_attr(&dom, "data-state").as_deref(),
            Some("ready"),
            "{url}"
        );
        assert_eq!(
            body_attr(&dom, "data-step"),
            Some(want.to_string()),
            "{url}"
        );
        assert_eq!(
            body_attr(&dom, "data-exploded").as_deref(),
            Some(exploded),
            "{url}"
        );
        assert!(console.is_empty(), "{url}: {console:#?}");
    }
    // Without WebGL the page says so, and the step lists still work.
    let url = format!("file://{}#step=2", page.display());
    let (dom, _) = chromium(&profile, &url, &["--disable-3d-apis", "--dump-dom"]);
    assert_eq!(body_attr(&dom, "data-state").as_deref(), Some("error"));
    assert_eq!(body_attr(&dom, "data-step").as_deref(), Some("2"));
    assert!(dom.contains("needs WebGL"), "{dom}");
}

/// A page beside the viewer that drives it in a frame the way a person
/// would (keys, buttons, the slider, the address, a drag, the wheel, the
/// explode toggle) and writes what the viewer showed after each action
/// into its own `<body data-log>`.
const HARNESS: &str = r##"<!DOCTYPE html>
<html><body data-log="">
<iframe id="f" width="900" height="650"></iframe>
<script>
var f = document.getElementById("f"), log = [];
function note(what) {
  var b = f.contentDocument.body;
  log.push(what + "=" + b.getAttribute("data-step") + "/" + b.getAttribute("data-exploded") +
    "/" + b.getAttribute("data-state") + "/" + f.contentWindow.location.hash);
}
function key(k) {
  f.contentWindow.dispatchEvent(new f.contentWindow.KeyboardEvent("keydown", { key: k, bubbles: true }));
}
function pointer(type, x, y, buttons) {
  var w = f.contentWindow, c = f.contentDocument.getElementById("view");
  c.dispatchEvent(new w.PointerEvent(type, { pointerId: 7, clientX: x, clientY: y, button: 0,
    buttons: buttons, bubbles: true, cancelable: true }));
}
f.onload = function () {
  var d = f.contentDocument, w = f.contentWindow;
  note("open");
  key("ArrowRight"); note("right");
  key("ArrowRight"); note("right");
  key("ArrowLeft"); note("left");
  d.getElementById("next").click(); note("next");
  d.getElementById("prev").click(); note("prev");
  key("End"); note("end");
  d.getElementById("first").click(); note("first");
  var s = d.getElementById("slider");
  s.value = "3"; s.dispatchEvent(new w.Event("input", { bubbles: true })); note("slider");
  pointer("pointerdown", 300, 300, 1); pointer("pointermove", 360, 320, 1); pointer("pointerup", 360, 320, 0);
  d.getElementById("view").dispatchEvent(new w.WheelEvent("wheel", { deltaY: 120, bubbles: true, cancelable: true }));
  note("drag");
  d.getElementById("explode").click(); note("explode");
  w.location.hash = "#step=2";
  setTimeout(function () {
    note("hash");
    document.body.setAttribute("data-log", log.join(" "));
  }, 300);
};
f.src = "PAGE#step=1";
</script>
</body></html>
"##;

#[test]
fn keys_buttons_slider_and_address_move_between_steps() {
    let tmp = tempfile::tempdir().unwrap();
    let (page, steps) = build_page("house.obj", 10, tmp.path());
    assert!(steps >= 4, "{steps} steps");
    if !common::required_tool("chromium", "chromium", "--version") {
        return;
    }
    let harness = tmp.path().join("harness.html");
    let name = page.file_name().unwrap().to_string_lossy();
    std::fs::write(&harness, HARNESS.replace("PAGE", &name)).unwrap();
    let url = format!("file://{}", harness.display());
    // The frame's document is readable only with file access between files.
    let profile = tmp.path().join("profile");
    // As in `chromium`: a frame still `loading` when the harness ran (the
    // software WebGL's start-up is on real time) is taken again, up to
    // three times.
    let mut tries = 0;
    let (dom, console, log) = loop {
        let (dom, console) = chromium(
            &profile,
            &url,
            &["--allow-file-access-from-files", "--dump-dom"],
        );
        let log = body_attr(&dom, "data-log").unwrap_or_default();
        tries += 1;
        if tries >= 3 || !log.contains("/loading/") {
            break (dom, console, log);
        }
    };
    assert!(console.is_empty(), "the console says {console:#?}");
    let want = [
        "open=1/0/ready/#step=1".to_string(),
        "right=2/0/ready/#step=2".into(),
        "right=3/0/ready/#step=3".into(),
        "left=2/0/ready/#step=2".into(),
        "next=3/0/ready/#step=3".into(),
        "prev=2/0/ready/#step=2".into(),
        format!("end={steps}/0/ready/#step={steps}"),
        "first=1/0/ready/#step=1".into(),
        "slider=3/0/ready/#step=3".into(),
        "drag=3/0/ready/#step=3".into(),
        "explode=3/1/ready/#step=3&amp;exploded=1".into(),
        "hash=2/1/ready/#step=2".into(),
    ];
    assert_eq!(log.split(' ').collect::<Vec<_>>(), want, "{dom}");
}

/// The page that holds the viewer page in a 1000x750 frame at the window's
/// top left and, once the viewer is no longer loading (or after 90 s) and
/// has drawn, logs `viewer-test: STATE/STEP` to the console.
const FIREFOX_HARNESS: &str = r##"<!DOCTYPE html>
<html><head><style>
body { margin: 0; overflow: hidden; }
iframe { border: 0; width: 1000px; height: 750px; position: absolute; left: 0; top: 0; }
</style></head>
<body><iframe id="f"></iframe>
<script>
var f = document.getElementById("f"), started = Date.now();
f.src = "PAGE";
function state() {
  var b = f.contentDocument && f.contentDocument.body;
  return (b && b.getAttribute("data-state") || "loading") + "/" + (b && b.getAttribute("data-step"));
}
function poll() {
  if (state().indexOf("loading") === 0 && Date.now() - started < 90000) {
    setTimeout(poll, 200);
    return;
  }
  // Two frames more, and a moment: the last drawing is on the screen.
  requestAnimationFrame(function () {
    requestAnimationFrame(function () {
      setTimeout(function () { console.log("viewer-test: " + state()); }, 500);
    });
  });
}
poll();
</script>
</body></html>
"##;

/// Firefox's settings for a test: the page's console on standard output,
/// frames of local files readable by the page around them, and none of
/// the browser's own network traffic.
const FIREFOX_PREFS: &str = r#"user_pref("devtools.console.stdout.content", true);
user_pref("security.fileuri.strict_origin_policy", false);
user_pref("browser.shell.checkDefaultBrowser", false);
user_pref("browser.startup.homepage_override.mstone", "ignore");
user_pref("datareporting.policy.dataSubmissionEnabled", false);
user_pref("toolkit.telemetry.reportingpolicy.firstRun", false);
user_pref("app.update.disabledForTesting", true);
user_pref("services.settings.server", "data:,#remote-settings-dummy/v1");
user_pref("browser.safebrowsing.update.enabled", false);
user_pref("extensions.update.enabled", false);
user_pref("network.captive-portal-service.enabled", false);
user_pref("network.connectivity-service.enabled", false);
user_pref("network.proxy.type", 0);
"#;

/// Processes ended when the test ends, however it ends.
struct Reaped(Vec<Child>);

impl Drop for Reaped {
    fn drop(&mut self) {
        // Firefox first, then the X server it draws on.
        for child in self.0.iter_mut().rev() {
            let _ = child.kill();
            let _ = child.wait();
        }
    }
}

/// Starts a virtual X server on a free display; its number.
fn start_xvfb(procs: &mut Reaped) -> String {
    let mut xvfb = Command::new("Xvfb")
        .args([
            "-displayfd",
            "1",
            "-screen",
            "0",
            "1280x900x24",
            "-nolisten",
            "tcp",
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .expect("Xvfb runs");
    let out = xvfb.stdout.take().unwrap();
    procs.0.push(xvfb);
    let mut line = String::new();
    BufReader::new(out).read_line(&mut line).unwrap();
    let display = line.trim().to_string();
    assert!(!display.is_empty(), "Xvfb named no display");
    format!(":{display}")
}

/// Firefox showing `page#step=STEP` on `display`: the viewer's state and
/// step as the harness saw them, the console lines and a screenshot.
fn firefox_shot(
    dir: &Path,
    display: &str,
    page: &Path,
    step: u32,
) -> (String, Vec<String>, PathBuf) {
    let profile = dir.join(format!("firefox-{step}"));
    std::fs::create_dir_all(&profile).unwrap();
    std::fs::write(profile.join("user.js"), FIREFOX_PREFS).unwrap();
    let harness = dir.join(format!("firefox-{step}.html"));
    let target = format!(
        "{}#step={step}",
        page.file_name().unwrap().to_string_lossy()
    );
    std::fs::write(&harness, FIREFOX_HARNESS.replace("PAGE", &target)).unwrap();
    let _turn = ONE_BROWSER.lock().unwrap_or_else(|e| e.into_inner());
    let mut procs = Reaped(Vec::new());
    let mut firefox = Command::new("firefox-esr")
        .args(["--no-remote", "--kiosk", "--profile"])
        .arg(&profile)
        .arg(format!("file://{}", harness.display()))
        .env("DISPLAY", display)
        .env_remove("MOZ_HEADLESS")
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("firefox-esr runs");
    let (tx, rx) = mpsc::channel();
    for pipe in [
        Box::new(firefox.stdout.take().unwrap()) as Box<dyn std::io::Read + Send>,
        Box::new(firefox.stderr.take().unwrap()),
    ] {
        let tx = tx.clone();
        std::thread::spawn(move || {
            for line in BufReader::new(pipe).lines().map_while(Result::ok) {
                if tx.send(line).is_err() {
                    break;
                }
            }
        });
    }
    procs.0.push(firefox);
    let mut lines = Vec::new();
    let state = loop {
        match rx.recv_timeout(Duration::from_secs(150)) {
            Ok(line) => {
                if let Some(rest) = line.split("viewer-test: ").nth(1) {
                    break rest.trim_end_matches('"').to_string();
                }
                lines.push(line);
            }
            Err(e) => panic!("firefox said nothing of the viewer ({e}): {lines:#?}"),
        }
    };
    let png = dir.join(format!("firefox-step-{step}.png"));
    let shot = Command::new("import")
        .args(["-display", display, "-window", "root"])
        .arg(&png)
        .output()
        .expect("import runs");
    assert!(
        shot.status.success(),
        "import: {}",
        String::from_utf8_lossy(&shot.stderr)
    );
    drop(procs);
    // The page's own messages: its console calls and the script errors and
    // warnings (WebGL's among them) that name a file of the test.
    let dir_url = format!("file://{}", dir.display());
    let console = lines
        .into_iter()
        .filter(|l| {
            l.starts_with("console.error: \"")
                || l.starts_with("console.warn: \"")
                || (l.starts_with("JavaScript") && l.contains(&dir_url))
        })
        .collect();
    (state, console, png)
}

#[test]
fn firefox_shows_the_first_and_the_last_step() {
    let tmp = tempfile::tempdir().unwrap();
    let (page, steps) = build_page("house.obj", 10, tmp.path());
    let tools = [
        ("firefox-esr", "firefox-esr", "--version"),
        ("Xvfb", "xvfb", "-help"),
        ("import", "imagemagick", "-version"),
    ];
    if !tools
        .iter()
        .all(|&(n, p, v)| common::required_tool(n, p, v))
    {
        return;
    }
    let mut xvfb = Reaped(Vec::new());
    let display = start_xvfb(&mut xvfb);
    let mut shots = Vec::new();
    for step in [1, steps] {
        let (state, console, png) = firefox_shot(tmp.path(), &display, &page, step);
        assert_eq!(state, format!("ready/{step}"), "firefox at step {step}");
        assert!(console.is_empty(), "firefox at step {step}: {console:#?}");
        shots.push(shows_the_model(&png, step, "firefox"));
    }
    first_and_last_differ(&shots);
}
