//! The step viewer page in a real browser: a fixture is built with
//! `--formats html`, and headless Chromium (Debian's `chromium`, WebGL
//! through SwiftShader, every host name unresolvable) opens the page at the
//! first and the last step. The page must come up (`data-state="ready"` at
//! the step the URL asks for), log nothing to the console, and draw the
//! model: the two screenshots show it, with the current step outlined, and
//! differ. The page itself must name no URL.
//!
//! Chromium is required: without it the test fails, unless
//! `BRICKWRIGHT_SKIP_TOOLS=1` asks to skip (`.ci/run` installs it).

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

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

fn chromium_once(profile: &Path, url: &str, args: &[&str]) -> (String, Vec<String>) {
    // One browser at a time: three software-rendering browsers at once on
    // two cores can miss the page's ready state within the time budget.
    static ONE_AT_A_TIME: std::sync::Mutex<()> = std::sync::Mutex::new(());
    let _turn = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
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

/// Pixels of the 3D view (the page's left part) in an RGB screenshot.
fn view_pixels(png: &Path) -> Vec<[u8; 3]> {
    let img = image::open(png)
        .unwrap_or_else(|e| panic!("{}: {e}", png.display()))
        .to_rgb8();
    assert_eq!(img.dimensions(), (1000, 750), "{}", png.display());
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
    let background = [0xee, 0xf0, 0xf3];
    let highlight = [0xff, 0x9e, 0x00];
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
        let px = view_pixels(&png);
        let model = px.iter().filter(|&&p| far(p, background, 24)).count();
        let outlined = px.iter().filter(|&&p| !far(p, highlight, 40)).count();
        assert!(model * 50 > px.len(), "step {step}: {model} model pixels");
        assert!(outlined > 100, "step {step}: {outlined} highlight pixels");
        if std::env::var_os("VIEWER_SHOTS").is_some() {
            let keep = PathBuf::from(std::env::var_os("VIEWER_SHOTS").unwrap());
            std::fs::create_dir_all(&keep).unwrap();
            std::fs::copy(&png, keep.join(format!("step-{step}.png"))).unwrap();
        }
        shots.push((model, px));
    }
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
    let (dom, console) = chromium(
        &profile,
        &url,
        &["--allow-file-access-from-files", "--dump-dom"],
    );
    assert!(console.is_empty(), "the console says {console:#?}");
    let log = body_attr(&dom, "data-log").unwrap_or_default();
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
