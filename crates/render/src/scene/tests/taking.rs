//! `create_scene_taking_entities`: the object instances and animated
//! shapes taken from the description (and freed as they are made) give
//! the scene, and the problems in the files' order, that reading them
//! from the description gives.

use super::super::assemble::{create_scene, create_scene_taking_entities, CreateOptions};
use super::{build_scene_from_str, BuildOptions};
use crate::scene::entities::SceneDescription;
use rpbrt_geometry::float::Float;
use rpbrt_geometry::ray::Ray;
use rpbrt_geometry::tuple::{Point3f, Vector3f};

fn described(text: &str) -> SceneDescription {
    match build_scene_from_str(text, &BuildOptions::default()) {
        Ok((desc, _)) => desc,
        Err(d) => panic!("{}", d.render()),
    }
}

/// A moving shape at `x` between the shutter's ends, its shape `shape`.
fn moving(x: i32, shape: &str) -> String {
    format!(
        "AttributeBegin\nActiveTransform StartTime\nTranslate {x} 0 0\nActiveTransform EndTime\nTranslate {x} 1 0\nActiveTransform All\n{shape}\nAttributeEnd\n"
    )
}

const HEAD: &str = "Camera \"perspective\" \"float shutteropen\" 0 \"float shutterclose\" 1\nFilm \"rgb\" \"integer xresolution\" 4 \"integer yresolution\" 4\nWorldBegin\n";

#[test]
fn taken_entities_give_the_same_scene_and_problems_in_order() {
    // A valid scene: moving shapes (one with a parameter nothing uses)
    // and instances.
    let mut text = HEAD.to_string();
    text += "ObjectBegin \"o\"\nShape \"sphere\" \"float radius\" 0.5\nObjectEnd\n";
    for x in 0..5 {
        text += &moving(x, "Shape \"sphere\" \"float radius\" 0.25");
        text += &format!("AttributeBegin\nTranslate 0 {x} 3\nObjectInstance \"o\"\nAttributeEnd\n");
    }
    text += &moving(9, "Shape \"sphere\" \"float bogus\" 1");
    let read = describe_created(create_scene(&described(&text), &CreateOptions::default()));
    let mut desc = described(&text);
    let taken = describe_created(create_scene_taking_entities(
        &mut desc,
        &CreateOptions::default(),
    ));
    assert_eq!(read, taken);
    assert!(desc.instances.is_empty() && desc.animated_shapes.is_empty());
    assert!(read.contains("bogus"), "{read}");

    // Fixed and moving instances interleaved: runs of fixed ones become
    // sets; taken from the end, the runs and their instances are put back
    // in order (the same entries, so the same hits).
    let mut text = HEAD.to_string();
    text += "ObjectBegin \"o\"\nShape \"sphere\" \"float radius\" 0.3\nObjectEnd\n";
    for x in 0..7 {
        for y in 0..3 {
            text += &format!(
                "AttributeBegin\nTranslate {x} {y} 3\nObjectInstance \"o\"\nAttributeEnd\n"
            );
        }
        text += &format!(
            "AttributeBegin\nActiveTransform StartTime\nTranslate {x} 4 3\nActiveTransform EndTime\nTranslate {x} 5 3\nActiveTransform All\nObjectInstance \"o\"\nAttributeEnd\n"
        );
    }
    let scene =
        |r: Result<crate::scene::assemble::CreatedScene, Vec<rpbrt_parser::Diagnostic>>| match r {
            Ok(c) => c.scene,
            Err(e) => panic!("{e:?}"),
        };
    let read = scene(create_scene(&described(&text), &CreateOptions::default()));
    let taken = scene(create_scene_taking_entities(
        &mut described(&text),
        &CreateOptions::default(),
    ));
    assert_eq!(read.aggregate.primitives().len(), 14);
    assert_eq!(read.aggregate.entry_count(), 28);
    assert_eq!(taken.aggregate.entry_count(), 28);
    let mut hits = 0;
    for i in 0..40 {
        for j in 0..40 {
            let o = Point3f::new(i as Float * 0.2 - 1.0, j as Float * 0.2 - 1.0, -5.0);
            let ray = Ray::with_time(o, Vector3f::new(0.3, 0.2, 1.0), 0.5, None);
            let a = read.aggregate.intersect_record(&ray, Float::INFINITY);
            assert_eq!(a, taken.aggregate.intersect_record(&ray, Float::INFINITY));
            hits += usize::from(a.is_some());
        }
    }
    assert!(hits > 30, "{hits}");

    // Errors: two broken moving meshes, reported in the files' order
    // either way.
    let mut text = HEAD.to_string();
    let broken = |i: i32| {
        format!(
            "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0] \"integer indices\" [0 1 {i}]"
        )
    };
    text += &moving(0, &broken(7));
    text += &moving(1, "Shape \"sphere\"");
    text += &moving(2, &broken(8));
    let errors =
        |r: Result<crate::scene::assemble::CreatedScene, Vec<rpbrt_parser::Diagnostic>>| match r {
            Ok(_) => panic!("the scene has errors"),
            Err(e) => e.iter().map(|d| d.to_string()).collect::<Vec<_>>(),
        };
    let read = errors(create_scene(&described(&text), &CreateOptions::default()));
    let taken = errors(create_scene_taking_entities(
        &mut described(&text),
        &CreateOptions::default(),
    ));
    assert_eq!(read, taken);
    // `<string>:line:column: error: ...`, the lines in order.
    let lines: Vec<u32> = read
        .iter()
        .filter_map(|e| e.split(':').nth(1)?.parse().ok())
        .collect();
    assert!(lines.len() >= 2 && lines.len() == read.len(), "{read:?}");
    assert!(lines.windows(2).all(|w| w[0] < w[1]), "{read:?}");
}

/// What a created scene is made of, as text: its primitives' count and
/// bounds, its warnings.
fn describe_created(
    r: Result<crate::scene::assemble::CreatedScene, Vec<rpbrt_parser::Diagnostic>>,
) -> String {
    let c = match r {
        Ok(c) => c,
        Err(e) => panic!("{e:?}"),
    };
    let warnings: Vec<String> = c.warnings.iter().map(|d| d.to_string()).collect();
    format!(
        "{} primitives, bounds {:?}, warnings {warnings:?}",
        c.scene.aggregate.primitives().len(),
        c.scene.aggregate.bounds()
    )
}
