//! The last stages: the booklet's pages, and every output written at once.

use super::pictures::{self, Pictures, Rendered};
use super::stability::Settled;
use super::{options::describe, BuildError, BuildOptions, BuildReport, Format};
use crate::booklet::Template;
use crate::export::gltf::{write_gltf, Container, GltfOptions};
use crate::export::html::{write_html, HtmlOptions};
use crate::export::partslist::{write_bricklink, write_rebrickable_csv, PartsList};
use crate::fsutil::{refuse_link, CreatedDirs, Outputs};
use crate::grammar::RuleSet;
use crate::ldraw::{write_ldr, LdrMeta};

/// The booklet: its PDF and page count.
pub(super) fn booklet(
    opts: &BuildOptions,
    pictures: &Pictures<'_>,
    rendered: &Rendered,
    template: &Template,
) -> Result<pictures::Booklet, BuildError> {
    pictures::booklet(pictures, rendered, template).map_err(|reason| BuildError::Write {
        path: opts
            .out_dir
            .join(Format::Pdf.file_name(pictures.title))
            .display()
            .to_string(),
        reason,
    })
}

/// The `.ldr` file's header: what made it, from what, how.
fn ldr_meta(
    opts: &BuildOptions,
    pictures: &Pictures<'_>,
    settled: &Settled,
    rules: &RuleSet,
) -> LdrMeta {
    let stem = pictures.title;
    // Each piece's rule; support columns added after the search have none.
    let by_piece = crate::search::piece_rules(&settled.outcome.order, rules);
    let piece_notes = settled
        .assembly
        .pieces
        .iter()
        .enumerate()
        .filter_map(|(i, p)| Some((i, format!("rule {}", by_piece.get(&p.placement)?))))
        .collect();
    LdrMeta {
        title: format!("{stem}, built by brickwright"),
        name: format!("{stem}.ldr"),
        author: "brickwright".into(),
        notes: vec![
            format!("brickwright {}", env!("CARGO_PKG_VERSION")),
            format!(
                "input: {}",
                opts.input
                    .file_name()
                    .map(|s| s.to_string_lossy())
                    .unwrap_or_default()
            ),
            format!("options: {}", describe(opts)),
            format!("seed: {}", opts.search.seed),
        ],
        step_notes: pictures.step_notes.clone(),
        piece_notes,
    }
}

/// Writes every output `opts.formats` names and `report.json` into
/// `opts.out_dir`. Every file is staged first and renamed into place
/// together, so a failed run leaves none of them (and no folder this run
/// made), and an interrupted one is finished or undone by the next
/// ([`Outputs`]). Returns the report as written: with its outputs and
/// write time.
pub(super) fn write(
    opts: &BuildOptions,
    rules: &RuleSet,
    settled: &Settled,
    pictures: &Pictures<'_>,
    rendered: Option<&Rendered>,
    booklet: Option<&[u8]>,
    mut report: BuildReport,
) -> Result<BuildReport, BuildError> {
    let t = std::time::Instant::now();
    let stem = pictures.title;
    let assembly = &settled.assembly;
    let failed = |path: &std::path::Path| {
        let path = path.display().to_string();
        move |reason| BuildError::Write { path, reason }
    };
    let mut made = CreatedDirs::new();
    made.create(&opts.out_dir).map_err(failed(&opts.out_dir))?;
    let report_path = opts.out_dir.join("report.json");
    let meta = ldr_meta(opts, pictures, settled, rules);
    let parts = PartsList::of(assembly);
    let mut files = Outputs::new(&opts.out_dir).map_err(failed(&opts.out_dir))?;
    for format in opts.formats.iter() {
        let path = opts.out_dir.join(format.file_name(stem));
        let written = match (format, rendered) {
            (Format::Ldr, _) => files.add(&path, |w| write_ldr(w, assembly, &meta)),
            (Format::Glb | Format::ExplodedGlb | Format::Gltf, _) => {
                let gltf = GltfOptions::default()
                    .with_name(stem)
                    .with_exploded(format == Format::ExplodedGlb)
                    .with_container(if format == Format::Gltf {
                        Container::Embedded
                    } else {
                        Container::Binary
                    });
                files.add(&path, |w| write_gltf(w, assembly, &gltf))
            }
            (Format::Bricklink, _) => {
                files.add(&path, |w| write_bricklink(w, &parts, opts.condition))
            }
            (Format::Csv, _) => files.add(&path, |w| write_rebrickable_csv(w, &parts)),
            (Format::Html, _) => files.add(&path, |w| {
                write_html(w, assembly, &HtmlOptions::default().with_name(stem))
            }),
            (Format::Stress, _) => {
                // Drawn only when the stability stage ran (`all` skips it
                // under `--stability off`; naming it then is an error).
                let Some((_, finished)) = &settled.stability else {
                    continue;
                };
                let png = pictures::encode(&pictures::stress_image(assembly, finished)?);
                files.add(&path, |w| w.write_all(&png))
            }
            (Format::Steps, Some(rendered)) => {
                // Never through a link to a folder outside `-o`.
                refuse_link(&path)
                    .and_then(|()| made.create(&path))
                    .map_err(failed(&path))?;
                // Each picture encoded and written on its own thread.
                let paths = pictures::step_paths(&path, rendered.steps.len());
                files.add_all(&paths, |k, w| {
                    w.write_all(&pictures::encode(&rendered.steps[k]))
                })
            }
            (Format::Png, Some(rendered)) => {
                let png = pictures::encode(&rendered.model);
                files.add(&path, |w| w.write_all(&png))
            }
            (Format::ExplodedPng, Some(rendered)) => {
                let png = pictures::encode(&rendered.exploded);
                files.add(&path, |w| w.write_all(&png))
            }
            (Format::Pdf, Some(_)) => {
                files.add(&path, |w| w.write_all(booklet.unwrap_or_default()))
            }
            (Format::Steps | Format::Png | Format::ExplodedPng | Format::Pdf, None) => {
                unreachable!("pictures are rendered when a pictured format is asked for")
            }
        };
        written.map_err(failed(&path))?;
    }
    report.outputs = files
        .paths()
        .chain([report_path.as_path()])
        .map(|p| p.display().to_string())
        .collect();
    report.seconds.write = super::secs(t);
    files
        .add(&report_path, |w| {
            serde_json::to_writer_pretty(&mut *w, &report).map_err(std::io::Error::other)?;
            w.write_all(b"\n")
        })
        .map_err(failed(&report_path))?;
    files
        .commit()
        .map_err(|(path, reason)| failed(&path)(reason))?;
    made.keep();
    if let Some(rendered) = rendered {
        if opts.formats.contains(Format::Steps) {
            pictures::remove_stale_steps(&opts.out_dir.join("steps"), rendered.steps.len());
        }
    }
    Ok(report)
}
