//! The `Accelerator` directive: which structure the scene gets, and
//! `"embree"` in builds without Embree.

use super::super::assemble::{create_scene, CreateOptions};
use super::{build_scene_from_str, BuildOptions};
use crate::accel::Accelerator;

const SCENE: &str = r#"Accelerator "embree" "integer maxnodeprims" 2
Camera "perspective"
Film "rgb" "integer xresolution" 4 "integer yresolution" 4
WorldBegin
Shape "sphere"
"#;

#[cfg(not(feature = "embree"))]
#[test]
fn embree_without_the_feature_warns_and_uses_the_bvh() {
    let (desc, _) = match build_scene_from_str(SCENE, &BuildOptions::default()) {
        Ok(d) => d,
        Err(d) => panic!("{}", d.render()),
    };
    let created = match create_scene(&desc, &CreateOptions::default()) {
        Ok(c) => c,
        Err(e) => panic!("{e:?}"),
    };
    assert!(matches!(
        created.scene.aggregate.accelerator(),
        Accelerator::Bvh8(_)
    ));
    let w: Vec<String> = created.warnings.iter().map(|d| d.to_string()).collect();
    // One located warning, at the directive; its (ignored) parameters are
    // not reported again as unused.
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(
        w[0].contains(":1:1: warning: \"embree\": this build has no Embree; using \"bvh\""),
        "{w:?}"
    );
}

#[cfg(feature = "embree")]
#[test]
fn embree_with_the_feature_reports_unknown_parameters() {
    let (desc, _) = match build_scene_from_str(SCENE, &BuildOptions::default()) {
        Ok(d) => d,
        Err(d) => panic!("{}", d.render()),
    };
    let Err(e) = create_scene(&desc, &CreateOptions::default()) else {
        panic!("\"maxnodeprims\" accepted by Embree");
    };
    assert!(
        e.iter()
            .any(|d| d.message.contains("\"maxnodeprims\": not a parameter")),
        "{e:?}"
    );
    let plain = SCENE.replace(" \"integer maxnodeprims\" 2", "");
    let (desc, _) = match build_scene_from_str(&plain, &BuildOptions::default()) {
        Ok(d) => d,
        Err(d) => panic!("{}", d.render()),
    };
    let created = match create_scene(&desc, &CreateOptions::default()) {
        Ok(c) => c,
        Err(e) => panic!("{e:?}"),
    };
    assert!(created.warnings.is_empty(), "{:?}", created.warnings);
    assert!(matches!(
        created.scene.aggregate.accelerator(),
        Accelerator::Embree(_)
    ));
}
