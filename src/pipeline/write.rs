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
use rayon::prelude::*;

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

/// Whether `format` is an output that needs no picture: made by
/// [`data_outputs`], beside the pictures.
fn is_data(format: Format) -> bool {
    matches!(
        format,
        Format::Ldr
            | Format::Glb
            | Format::ExplodedGlb
            | Format::Gltf
            | Format::Bricklink
            | Format::Csv
            | Format::Html
    )
}

/// The bytes of each output `opts.formats` names that needs no picture
/// (the `.ldr`, the glTF files, the parts lists, the HTML page), made in
/// memory in parallel: the pipeline makes them while the pictures are
/// drawn, and [`write`] stages them.
pub(super) fn data_outputs(
    opts: &BuildOptions,
    rules: &RuleSet,
    settled: &Settled,
    pictures: &Pictures<'_>,
) -> Vec<(Format, std::io::Result<Vec<u8>>)> {
    let stem = pictures.title;
    let assembly = &settled.assembly;
    let meta = ldr_meta(opts, pictures, settled, rules);
    let parts = PartsList::of(assembly);
    let formats: Vec<Format> = opts.formats.iter().filter(|&f| is_data(f)).collect();
    formats
        .into_par_iter()
        .map(|format| {
            let mut out = Vec::new();
            let w: &mut dyn std::io::Write = &mut out;
            let made = match format {
                Format::Ldr => write_ldr(w, assembly, &meta),
                Format::Glb | Format::ExplodedGlb | Format::Gltf => {
                    let gltf = GltfOptions::default()
                        .with_name(stem)
                        .with_exploded(format == Format::ExplodedGlb)
                        .with_container(if format == Format::Gltf {
                            Container::Embedded
                        } else {
                            Container::Binary
                        });
                    write_gltf(w, assembly, &gltf)
                }
                Format::Bricklink => write_bricklink(w, &parts, opts.condition),
                Format::Csv => write_rebrickable_csv(w, &parts),
                Format::Html => write_html(w, assembly, &HtmlOptions::default().with_name(stem)),
                _ => unreachable!("only the outputs without pictures are made here"),
            };
            (format, made.map(|()| out))
        })
        .collect()
}

/// The pictures' PNG files' bytes: each step's (when asked for), the
/// finished model's and the exploded view's.
pub(super) struct Encoded {
    steps: Vec<Vec<u8>>,
    model: Vec<u8>,
    exploded: Vec<u8>,
}

/// Encodes the pictures `opts.formats` asks for as PNG, in parallel (the
/// pipeline does it while the booklet is laid out).
pub(super) fn encode_pictures(opts: &BuildOptions, rendered: &Rendered) -> Encoded {
    let wanted = |f: Format, img: &image::RgbaImage| {
        if opts.formats.contains(f) {
            pictures::encode(img)
        } else {
            Vec::new()
        }
    };
    let (steps, (model, exploded)) = rayon::join(
        || {
            if opts.formats.contains(Format::Steps) {
                pictures::encode_all(&rendered.steps)
            } else {
                Vec::new()
            }
        },
        || {
            rayon::join(
                || wanted(Format::Png, &rendered.model),
                || wanted(Format::ExplodedPng, &rendered.exploded),
            )
        },
    );
    Encoded {
        steps,
        model,
        exploded,
    }
}

/// Writes every output `opts.formats` names and `report.json` into
/// `opts.out_dir`: the bytes `data` (from [`data_outputs`]) and `encoded`
/// (from [`encode_pictures`]), the booklet, the stress picture. Every file
/// is staged first and renamed into place together, so a failed run
/// leaves none of them (and no folder this run made), and an interrupted
/// one is finished or undone by the next ([`Outputs`]). Returns the report
/// as written: with its outputs and write time.
#[allow(clippy::too_many_arguments)]
pub(super) fn write(
    opts: &BuildOptions,
    settled: &Settled,
    pictures: &Pictures<'_>,
    data: Vec<(Format, std::io::Result<Vec<u8>>)>,
    encoded: Option<&Encoded>,
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
    let mut data: std::collections::HashMap<Format, std::io::Result<Vec<u8>>> =
        data.into_iter().collect();
    let mut files = Outputs::new(&opts.out_dir).map_err(failed(&opts.out_dir))?;
    for format in opts.formats.iter() {
        let path = opts.out_dir.join(format.file_name(stem));
        let written = match (format, encoded) {
            (f, _) if is_data(f) => match data.remove(&f) {
                Some(Ok(bytes)) => files.add(&path, |w| w.write_all(&bytes)),
                Some(Err(e)) => Err(e),
                None => unreachable!("every output without pictures is made before writing"),
            },
            (Format::Stress, _) => {
                // Drawn only when the stability stage ran (`all` skips it
                // under `--stability off`; naming it then is an error).
                let Some((_, finished)) = &settled.stability else {
                    continue;
                };
                let png = pictures::encode(&pictures::stress_image(assembly, finished)?);
                files.add(&path, |w| w.write_all(&png))
            }
            (Format::Steps, Some(encoded)) => {
                // Never through a link to a folder outside `-o`.
                refuse_link(&path)
                    .and_then(|()| made.create(&path))
                    .map_err(failed(&path))?;
                // Each picture written on its own thread.
                let paths = pictures::step_paths(&path, encoded.steps.len());
                files.add_all(&paths, |k, w| w.write_all(&encoded.steps[k]))
            }
            (Format::Png, Some(encoded)) => files.add(&path, |w| w.write_all(&encoded.model)),
            (Format::ExplodedPng, Some(encoded)) => {
                files.add(&path, |w| w.write_all(&encoded.exploded))
            }
            (Format::Pdf, Some(_)) => {
                files.add(&path, |w| w.write_all(booklet.unwrap_or_default()))
            }
            (Format::Steps | Format::Png | Format::ExplodedPng | Format::Pdf, None) => {
                unreachable!("pictures are rendered when a pictured format is asked for")
            }
            _ => unreachable!("every format is written above"),
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
    if let Some(encoded) = encoded {
        if opts.formats.contains(Format::Steps) {
            pictures::remove_stale_steps(&opts.out_dir.join("steps"), encoded.steps.len());
        }
    }
    Ok(report)
}
