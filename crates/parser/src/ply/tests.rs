use super::header::Format;
use super::read::UV_NAMES;
use super::*;
use crate::input::is_gzip;
use std::io::Write;
use std::path::PathBuf;

/// Writes PLY bodies value by value in any of the three formats.
struct Body {
    format: Format,
    out: Vec<u8>,
}

macro_rules! put {
    ($name:ident, $t:ty) => {
        fn $name(&mut self, v: $t) -> &mut Self {
            match self.format {
                Format::Ascii => self.out.extend_from_slice(format!("{v} ").as_bytes()),
                Format::BinaryLittleEndian => self.out.extend_from_slice(&v.to_le_bytes()),
                Format::BinaryBigEndian => self.out.extend_from_slice(&v.to_be_bytes()),
            }
            self
        }
    };
}

impl Body {
    fn new(format: Format) -> Body {
        Body {
            format,
            out: Vec::new(),
        }
    }
    put!(i8, i8);
    put!(u8, u8);
    put!(i16, i16);
    put!(u16, u16);
    put!(i32, i32);
    put!(u32, u32);
    put!(f32, f32);
    put!(f64, f64);
    fn nl(&mut self) -> &mut Self {
        if self.format == Format::Ascii {
            self.out.push(b'\n');
        }
        self
    }
}

fn format_name(f: Format) -> &'static str {
    match f {
        Format::Ascii => "ascii",
        Format::BinaryLittleEndian => "binary_little_endian",
        Format::BinaryBigEndian => "binary_big_endian",
    }
}

const FORMATS: [Format; 3] = [
    Format::Ascii,
    Format::BinaryLittleEndian,
    Format::BinaryBigEndian,
];

fn file(format: Format, header_body: &str, body: &[u8]) -> Vec<u8> {
    let mut v = format!(
        "ply\nformat {} 1.0\ncomment test\n{header_body}end_header\n",
        format_name(format)
    )
    .into_bytes();
    v.extend_from_slice(body);
    v
}

/// A mesh exercising most of the reader: mixed types, skipped scalar and
/// list properties, a skipped element between vertex and face, and faces of
/// 3, 4, 5 and 2 vertices.
fn rich_file(format: Format) -> Vec<u8> {
    let header = "element vertex 5\n\
        property float x\nproperty float y\nproperty float z\n\
        property uchar confidence\n\
        property list uchar ushort tags\n\
        property double nx\nproperty double ny\nproperty double nz\n\
        property float u\nproperty float v\n\
        element material 2\nproperty list uint8 float32 rgb\nproperty int id\n\
        element face 4\n\
        property ushort flags\n\
        property list uchar int vertex_indices\n\
        property int face_indices\n";
    let mut b = Body::new(format);
    for i in 0..5 {
        let f = i as f32;
        b.f32(f).f32(f + 0.5).f32(-f).u8(200);
        b.u8(2).u16(7).u16(9);
        b.f64(0.0)
            .f64(0.0)
            .f64(1.0)
            .f32(f * 0.25)
            .f32(1.0 - f * 0.25)
            .nl();
    }
    for m in 0..2 {
        b.u8(3).f32(0.1).f32(0.2).f32(0.3).i32(m).nl();
    }
    b.u16(1).u8(3).i32(0).i32(1).i32(2).i32(10).nl();
    b.u16(1).u8(4).i32(0).i32(1).i32(2).i32(3).i32(11).nl();
    b.u16(1)
        .u8(5)
        .i32(0)
        .i32(1)
        .i32(2)
        .i32(3)
        .i32(4)
        .i32(12)
        .nl();
    b.u16(1).u8(2).i32(0).i32(1).i32(13).nl();
    file(format, header, &b.out)
}

#[test]
fn rich_file_in_every_format() {
    for format in FORMATS {
        let m = parse_ply(&rich_file(format)).unwrap();
        assert_eq!(m.positions.len(), 5, "{format:?}");
        assert_eq!(m.positions[3], [3.0, 3.5, -3.0]);
        assert_eq!(m.normals, vec![[0.0, 0.0, 1.0]; 5]);
        assert_eq!(m.uvs[2], [0.5, 0.5]);
        // Triangle, then the pentagon's fan; the quad in bilinear order.
        assert_eq!(m.tri_indices, vec![0, 1, 2, 0, 1, 2, 0, 2, 3, 0, 3, 4]);
        assert_eq!(m.quad_indices, vec![0, 1, 3, 2]);
        assert_eq!(m.face_indices, vec![10, 12, 12, 12, 11]);
        assert_eq!(m.warnings.len(), 3, "{:?}", m.warnings);
        assert!(m.warnings.iter().any(|w| w.contains(
            "ignored unused PLY data: vertex.confidence, vertex.tags, element \"material\", face.flags"
        )));
        assert!(m.warnings.iter().any(|w| w.contains("fans")));
        assert!(m.warnings.iter().any(|w| w.contains("fewer than 3")));
    }
}

fn tri_file(format: Format, vertex_props: &str, values: &[[f64; 5]]) -> Vec<u8> {
    let header = format!(
        "element vertex {}\n{vertex_props}element face 1\n\
         property list uchar uint vertex_indices\n",
        values.len()
    );
    let mut b = Body::new(format);
    for v in values {
        for &x in v {
            b.f32(x as f32);
        }
        b.nl();
    }
    b.u8(3).u32(0).u32(1).u32(2);
    file(format, &header, &b.out)
}

#[test]
fn uv_aliases() {
    for (u, v) in UV_NAMES {
        let props = format!(
            "property float x\nproperty float y\nproperty float z\n\
             property float {u}\nproperty float {v}\n"
        );
        let vals = [
            [0., 0., 0., 0.1, 0.2],
            [1., 0., 0., 0.3, 0.4],
            [0., 1., 0., 0.5, 0.6],
        ];
        for format in FORMATS {
            let m = parse_ply(&tri_file(format, &props, &vals)).unwrap();
            assert_eq!(
                m.uvs,
                vec![[0.1, 0.2], [0.3, 0.4], [0.5, 0.6]],
                "{u} {format:?}"
            );
            assert!(m.normals.is_empty());
        }
    }
    // An incomplete pair is not a uv.
    let props = "property float x\nproperty float y\nproperty float z\n\
                 property float u\nproperty float t\n";
    let vals = [[0.; 5]; 3];
    let m = parse_ply(&tri_file(Format::BinaryLittleEndian, props, &vals)).unwrap();
    assert!(m.uvs.is_empty());
}

#[test]
fn every_scalar_type() {
    let names = [
        ["char", "uchar", "short"],
        ["ushort", "int", "uint"],
        ["float", "double", "int8"],
        ["uint8", "int16", "uint16"],
        ["int32", "uint32", "float32"],
        ["float64", "float", "float"],
    ];
    for format in FORMATS {
        for [a, b, c] in names {
            let header = format!(
                "element vertex 3\nproperty {a} x\nproperty {b} y\nproperty {c} z\n\
                 element face 1\nproperty list uchar int vertex_indices\n"
            );
            let mut body = Body::new(format);
            for i in 0..3u8 {
                for ty in [a, b, c] {
                    match ty {
                        "char" | "int8" => body.i8(i as i8 - 1),
                        "uchar" | "uint8" => body.u8(i),
                        "short" | "int16" => body.i16(i as i16 - 1),
                        "ushort" | "uint16" => body.u16(i as u16),
                        "int" | "int32" => body.i32(i as i32 - 1),
                        "uint" | "uint32" => body.u32(i as u32),
                        "float" | "float32" => body.f32(f32::from(i) + 0.5),
                        _ => body.f64(f64::from(i) + 0.25),
                    };
                }
                body.nl();
            }
            body.u8(3).i32(0).i32(1).i32(2);
            let m = parse_ply(&file(format, &header, &body.out)).unwrap();
            for (slot, ty) in [a, b, c].into_iter().enumerate() {
                let expect = |i: u8| match ty {
                    "char" | "int8" | "short" | "int16" | "int" | "int32" => f32::from(i) - 1.0,
                    "float" | "float32" => f32::from(i) + 0.5,
                    "double" | "float64" => f32::from(i) + 0.25,
                    _ => f32::from(i),
                };
                for i in 0..3u8 {
                    assert_eq!(m.positions[i as usize][slot], expect(i), "{ty} {format:?}");
                }
            }
        }
    }
}

fn sample_mesh() -> PlyMesh {
    PlyMesh {
        positions: vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.5, 0.5, 1.0],
        ],
        normals: vec![[0.0, 0.0, 1.0]; 5],
        uvs: vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [0.5, 0.5]],
        tri_indices: vec![0, 1, 4, 1, 2, 4],
        quad_indices: vec![0, 1, 3, 2],
        face_indices: vec![7, 8, 9],
        warnings: Vec::new(),
    }
}

fn temp_path(name: &str) -> PathBuf {
    std::env::temp_dir().join(format!("rpbrt-ply-test-{}-{name}", std::process::id()))
}

#[test]
fn write_read_round_trip() {
    let mut variants = vec![sample_mesh()];
    let mut m = sample_mesh();
    m.normals.clear();
    m.face_indices.clear();
    variants.push(m);
    let mut m = sample_mesh();
    m.uvs.clear();
    m.quad_indices.clear();
    m.face_indices.truncate(2);
    variants.push(m);
    variants.push(PlyMesh::default());
    for (i, mesh) in variants.iter().enumerate() {
        let bytes = encode_ply(mesh).unwrap();
        assert_eq!(&parse_ply(&bytes).unwrap(), mesh);
        for name in [format!("{i}.ply"), format!("{i}.ply.gz")] {
            let path = temp_path(&name);
            write_ply(&path, mesh).unwrap();
            let on_disk = std::fs::read(&path).unwrap();
            assert_eq!(is_gzip(&on_disk), name.ends_with(".gz"));
            assert_eq!(&read_ply(&path).unwrap(), mesh, "{name}");
            // Gzip is recognised by its magic bytes too, whatever the name.
            assert_eq!(&parse_ply(&on_disk).unwrap(), mesh);
            std::fs::remove_file(&path).unwrap();
        }
    }
}

#[test]
fn quads_use_bilinear_patch_order() {
    let mesh = sample_mesh();
    let bytes = encode_ply(&mesh).unwrap();
    // In the file the quad is a polygon 0 1 2 3.
    let header_end = bytes
        .windows(11)
        .position(|w| w == b"end_header\n")
        .unwrap()
        + 11;
    let quad = &bytes[header_end + 5 * 32 + 2 * 17..][..17];
    assert_eq!(quad[0], 4);
    let idx: Vec<i32> = quad[1..]
        .chunks(4)
        .map(|c| i32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect();
    assert_eq!(idx, vec![0, 1, 2, 3]);
    assert_eq!(parse_ply(&bytes).unwrap().quad_indices, vec![0, 1, 3, 2]);
}

#[test]
fn writer_rejects_inconsistent_meshes() {
    let cases: [fn(&mut PlyMesh); 6] = [
        |m| m.normals.truncate(4),
        |m| m.uvs.push([0.0, 0.0]),
        |m| m.tri_indices.push(0),
        |m| m.quad_indices.push(0),
        |m| m.face_indices.push(0),
        |m| m.tri_indices[0] = 5,
    ];
    for f in cases {
        let mut m = sample_mesh();
        f(&mut m);
        let e = encode_ply(&m).unwrap_err();
        assert!(matches!(e.kind, PlyErrorKind::InvalidMesh(_)), "{e}");
    }
}

#[test]
fn faces_before_vertices_and_general_layouts() {
    // ushort list counts and uint indices take the general binary path.
    for format in FORMATS {
        let header = "element face 2\nproperty list ushort uint vertex_index\n\
                      element vertex 4\nproperty double x\nproperty double y\nproperty double z\n\
                      property list uchar float extra\n";
        let mut b = Body::new(format);
        b.u16(3).u32(0).u32(1).u32(2).nl();
        b.u16(4).u32(0).u32(1).u32(2).u32(3).nl();
        for i in 0..4 {
            b.f64(i as f64).f64(0.0).f64(0.0).u8(1).f32(9.0).nl();
        }
        let m = parse_ply(&file(format, header, &b.out)).unwrap();
        assert_eq!(m.positions.len(), 4);
        assert_eq!(m.positions[3], [3.0, 0.0, 0.0]);
        assert_eq!(m.tri_indices, vec![0, 1, 2]);
        assert_eq!(m.quad_indices, vec![0, 1, 3, 2]);
        assert!(m.face_indices.is_empty());
        assert_eq!(m.warnings, ["ignored unused PLY data: vertex.extra"]);
    }
}

#[test]
fn fast_face_layout_with_face_indices_and_odd_faces() {
    for format in FORMATS {
        for (index_ty, fi_ty) in [("int", "int"), ("uint", "uint"), ("int", "uint")] {
            let header = format!(
                "element vertex 5\nproperty float x\nproperty float y\nproperty float z\n\
                 element face 5\nproperty list uchar {index_ty} vertex_indices\n\
                 property {fi_ty} face_indices\n"
            );
            let mut b = Body::new(format);
            for i in 0..15 {
                b.f32(i as f32);
            }
            let faces: [&[u32]; 5] = [
                &[0, 1, 2],
                &[1, 2, 3, 4],
                &[0, 1, 2, 3, 4],
                &[4],
                &[2, 3, 4],
            ];
            for (f, face) in faces.iter().enumerate() {
                b.u8(face.len() as u8);
                for &i in *face {
                    if index_ty == "int" {
                        b.i32(i as i32);
                    } else {
                        b.u32(i);
                    }
                }
                if fi_ty == "int" {
                    b.i32(100 + f as i32);
                } else {
                    b.u32(100 + f as u32);
                }
                b.nl();
            }
            let m = parse_ply(&file(format, &header, &b.out)).unwrap();
            assert_eq!(m.positions[4], [12.0, 13.0, 14.0]);
            assert_eq!(
                m.tri_indices,
                vec![0, 1, 2, 0, 1, 2, 0, 2, 3, 0, 3, 4, 2, 3, 4]
            );
            assert_eq!(m.quad_indices, vec![1, 2, 4, 3]);
            assert_eq!(m.face_indices, vec![100, 102, 102, 102, 104, 101]);
            assert_eq!(m.warnings.len(), 2, "{:?}", m.warnings);
        }
    }
    // A uint face index beyond i32 is reported, not wrapped.
    let header = "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
                  element face 1\nproperty list uchar int vertex_indices\n\
                  property uint face_indices\n";
    let mut b = Body::new(Format::BinaryLittleEndian);
    for _ in 0..9 {
        b.f32(0.0);
    }
    b.u8(3).i32(0).i32(1).i32(2).u32(u32::MAX);
    assert!(matches!(
        err_kind(&file(Format::BinaryLittleEndian, header, &b.out)),
        PlyErrorKind::BadValue { .. }
    ));
}

#[test]
fn crlf_header_and_trailing_data() {
    let mut bytes = encode_ply(&sample_mesh()).unwrap();
    let text = String::from_utf8_lossy(&bytes).into_owned();
    let header_len = text.find("end_header\n").unwrap() + 11;
    let crlf = text[..header_len].replace('\n', "\r\n");
    let mut v = crlf.into_bytes();
    v.extend_from_slice(&bytes[header_len..]);
    let m = parse_ply(&v).unwrap();
    assert_eq!(m, sample_mesh());
    bytes.extend_from_slice(b"junk");
    let m = parse_ply(&bytes).unwrap();
    assert_eq!(m.warnings.len(), 1);
    assert!(m.warnings[0].contains("4 bytes"));
}

#[test]
fn non_finite_coordinates_are_kept_with_a_warning() {
    let mut mesh = sample_mesh();
    mesh.positions[1][2] = f32::NAN;
    mesh.positions[2][0] = f32::INFINITY;
    let m = parse_ply(&encode_ply(&mesh).unwrap()).unwrap();
    assert!(m.positions[1][2].is_nan());
    assert_eq!(m.positions[2][0], f32::INFINITY);
    assert_eq!(m.warnings.len(), 1);
    assert!(m.warnings[0].starts_with("2 vertices"), "{:?}", m.warnings);
}

fn err_kind(bytes: &[u8]) -> PlyErrorKind {
    match parse_ply(bytes) {
        Ok(m) => panic!("expected an error, got {m:?}"),
        Err(e) => {
            assert!(e.to_string().starts_with("<memory>: "), "{e}");
            e.kind
        }
    }
}

#[test]
fn header_errors() {
    assert!(matches!(err_kind(b""), PlyErrorKind::BadMagic));
    assert!(matches!(err_kind(b"plyx\n"), PlyErrorKind::BadMagic));
    assert!(matches!(
        err_kind(b"PLY\nformat ascii 1.0\n"),
        PlyErrorKind::BadMagic
    ));
    let cases: &[(&str, usize)] = &[
        ("format ascii 1.0\nelement vertex 3\n", 3),
        ("format ascii 2.0\nend_header\n", 2),
        ("format utf8 1.0\nend_header\n", 2),
        ("format ascii 1.0\nformat ascii 1.0\nend_header\n", 3),
        ("element vertex 3\nend_header\n", 3),
        ("format ascii 1.0\nproperty float x\nend_header\n", 3),
        ("format ascii 1.0\nelement vertex -3\nend_header\n", 3),
        (
            "format ascii 1.0\nelement vertex 99999999999999999999999\nend_header\n",
            3,
        ),
        ("format ascii 1.0\nelement vertex\nend_header\n", 3),
        (
            "format ascii 1.0\nelement vertex 1\nproperty float128 x\nend_header\n",
            4,
        ),
        (
            "format ascii 1.0\nelement vertex 1\nproperty list float int x\nend_header\n",
            4,
        ),
        (
            "format ascii 1.0\nelement vertex 1\nproperty list int x\nend_header\n",
            4,
        ),
        (
            "format ascii 1.0\nelement vertex 1\nelement vertex 1\nend_header\n",
            4,
        ),
        ("format ascii 1.0\nvertices 3\nend_header\n", 3),
    ];
    for (text, line) in cases {
        let bytes = format!("ply\n{text}");
        match err_kind(bytes.as_bytes()) {
            PlyErrorKind::Header { line: l, .. } => assert_eq!(l, *line, "{text}"),
            k => panic!("{text}: unexpected {k}"),
        }
    }
}

#[test]
fn structural_errors() {
    let xyz = "property float x\nproperty float y\nproperty float z\n";
    let faces = "element face 0\nproperty list uchar int vertex_indices\n";
    let f = |h: String| file(Format::BinaryLittleEndian, &h, &[]);
    assert!(matches!(
        err_kind(&f(format!("element vertex 0\n{xyz}"))),
        PlyErrorKind::MissingElement("face")
    ));
    assert!(matches!(
        err_kind(&f(faces.to_string())),
        PlyErrorKind::MissingElement("vertex")
    ));
    assert!(matches!(
        err_kind(&f(format!(
            "element vertex 0\nproperty float x\nproperty float z\n{faces}"
        ))),
        PlyErrorKind::MissingProperty { property: "y", .. }
    ));
    assert!(matches!(
        err_kind(&f(format!(
            "element vertex 0\nproperty float x\nproperty float y\n\
             property list uchar float z\n{faces}"
        ))),
        PlyErrorKind::UnsupportedProperty { .. }
    ));
    assert!(matches!(
        err_kind(&f(format!(
            "element vertex 0\n{xyz}element face 0\nproperty list uchar int indices\n"
        ))),
        PlyErrorKind::MissingProperty {
            property: "vertex_indices",
            ..
        }
    ));
    assert!(matches!(
        err_kind(&f(format!(
            "element vertex 0\n{xyz}element face 0\nproperty int vertex_indices\n"
        ))),
        PlyErrorKind::UnsupportedProperty { .. }
    ));
    assert!(matches!(
        err_kind(&f(format!(
            "element vertex 0\n{xyz}{faces}property list uchar int face_indices\n"
        ))),
        PlyErrorKind::UnsupportedProperty { .. }
    ));
    // Zero vertices and faces is a valid, empty mesh.
    let m = parse_ply(&f(format!("element vertex 0\n{xyz}{faces}"))).unwrap();
    assert_eq!(m, PlyMesh::default());
}

#[test]
fn truncation_is_reported_with_counts() {
    for format in FORMATS {
        let full = rich_file(format);
        let header_len = full.windows(11).position(|w| w == b"end_header\n").unwrap() + 11;
        let mut truncations = 0;
        for cut in header_len..full.len() {
            let cut_bytes = &full[..cut];
            match parse_ply(cut_bytes) {
                Err(PlyError {
                    kind:
                        PlyErrorKind::Truncated {
                            element,
                            expected,
                            read,
                        },
                    ..
                }) => {
                    let n = match element.as_str() {
                        "vertex" => 5,
                        "material" => 2,
                        "face" => 4,
                        e => panic!("{e}"),
                    };
                    assert_eq!(expected, n);
                    assert!(read < n);
                    truncations += 1;
                }
                // ASCII cut inside the final number still parses.
                Ok(_) if format == Format::Ascii && cut + 4 >= full.len() => {}
                // ASCII cut right after a minus sign.
                Err(PlyError {
                    kind: PlyErrorKind::BadValue { message, .. },
                    ..
                }) if format == Format::Ascii && message.contains("'-'") => {}
                other => panic!("{format:?} cut at {cut}: {other:?}"),
            }
        }
        assert!(truncations > 10);
    }
}

#[test]
fn truncated_vertices_message() {
    let mut mesh = sample_mesh();
    mesh.positions.resize(10, [0.0; 3]);
    mesh.normals.clear();
    mesh.uvs.clear();
    let bytes = encode_ply(&mesh).unwrap();
    let header_len = bytes
        .windows(11)
        .position(|w| w == b"end_header\n")
        .unwrap()
        + 11;
    let path = temp_path("truncated.ply");
    std::fs::write(&path, &bytes[..header_len + 12 * 7 + 5]).unwrap();
    let e = read_ply(&path).unwrap_err();
    std::fs::remove_file(&path).unwrap();
    let msg = e.to_string();
    assert!(msg.starts_with(&path.display().to_string()), "{msg}");
    assert!(
        msg.ends_with("expected 10 vertices, file ends after 7"),
        "{msg}"
    );
    let missing = read_ply(&temp_path("does-not-exist.ply")).unwrap_err();
    assert!(matches!(missing.kind, PlyErrorKind::Io(_)));
    assert!(missing.to_string().contains("does-not-exist.ply"));
}

#[test]
fn index_out_of_range() {
    for format in FORMATS {
        for (count_ty, index_ty, bad) in [
            ("uchar", "int", 3i64),
            ("uchar", "int", -1),
            ("uchar", "uint", 3),
            ("ushort", "int", 3),
            ("ushort", "int", -2),
            ("uchar", "short", -5),
        ] {
            for quad in [false, true] {
                let header = format!(
                    "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
                     element face 2\nproperty list {count_ty} {index_ty} vertex_indices\n"
                );
                let mut b = Body::new(format);
                for _ in 0..9 {
                    b.f32(0.0);
                }
                let count = |b: &mut Body, n: u8| {
                    if count_ty == "uchar" {
                        b.u8(n);
                    } else {
                        b.u16(u16::from(n));
                    }
                };
                let idx = |b: &mut Body, i: i64| {
                    match index_ty {
                        "int" => b.i32(i as i32),
                        "uint" => b.u32(i as u32),
                        _ => b.i16(i as i16),
                    };
                };
                count(&mut b, 3);
                for i in 0..3 {
                    idx(&mut b, i);
                }
                count(&mut b, if quad { 4 } else { 3 });
                idx(&mut b, 0);
                idx(&mut b, bad);
                idx(&mut b, 1);
                if quad {
                    idx(&mut b, 2);
                }
                match err_kind(&file(format, &header, &b.out)) {
                    PlyErrorKind::IndexOutOfRange {
                        face,
                        index,
                        vertex_count,
                    } => {
                        assert_eq!((face, index, vertex_count), (1, bad, 3));
                    }
                    k => panic!("{format:?} {count_ty} {index_ty}: {k}"),
                }
            }
        }
    }
}

#[test]
fn bad_values() {
    let header = "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
                  element face 1\nproperty list uchar int vertex_indices\n";
    let body = b"0 0 0\n1 0 zero\n0 1 0\n3 0 1 2\n";
    match err_kind(&file(Format::Ascii, header, body)) {
        PlyErrorKind::BadValue {
            element, record, ..
        } => assert_eq!((element.as_str(), record), ("vertex", 1)),
        k => panic!("{k}"),
    }
    let body = b"0 0 0\n1 0 0\n0 1 0\n3 0 1.5 2\n";
    assert!(matches!(
        err_kind(&file(Format::Ascii, header, body)),
        PlyErrorKind::BadValue { .. }
    ));
    let body = b"0 0 0\n1 0 0\n0 1 0\n-3 0 1 2\n";
    assert!(matches!(
        err_kind(&file(Format::Ascii, header, body)),
        PlyErrorKind::BadValue { .. }
    ));
    // Integral floats are fine as indices.
    let body = b"0 0 0\n1 0 0\n0 1 0\n3 0 1.0 2e0\n";
    let m = parse_ply(&file(Format::Ascii, header, body)).unwrap();
    assert_eq!(m.tri_indices, vec![0, 1, 2]);
}

#[test]
fn absurd_counts_fail_fast_without_allocating() {
    let xyz = "property float x\nproperty float y\nproperty float z\n";
    let faces = "property list uchar int vertex_indices\n";
    let start = std::time::Instant::now();
    for format in FORMATS {
        for header in [
            format!("element vertex 2147483648\n{xyz}element face 1\n{faces}"),
            format!("element vertex 18446744073709551615\n{xyz}element face 1\n{faces}"),
            format!("element vertex 3\n{xyz}element face 1099511627776\n{faces}"),
            format!(
                "element junk 1152921504606846976\nproperty list uint uint a\n\
                 element vertex 3\n{xyz}element face 1\n{faces}"
            ),
            format!(
                "element junk 1152921504606846976\nproperty double a\n\
                 element vertex 3\n{xyz}element face 1\n{faces}"
            ),
        ] {
            let mut b = Body::new(format);
            for i in 0..9 {
                b.f32(i as f32);
            }
            b.u8(3).i32(0).i32(1).i32(2);
            let bytes = file(format, &header, &b.out);
            assert!(bytes.len() < 400);
            match err_kind(&bytes) {
                PlyErrorKind::Truncated { .. } => {}
                k => panic!("{format:?} {header}: {k}"),
            }
        }
        // A zero-property element may claim any count.
        let header = format!(
            "element nothing 18446744073709551615\nelement vertex 0\n{xyz}element face 0\n{faces}"
        );
        assert!(parse_ply(&file(format, &header, &[])).is_ok());
    }
    assert!(start.elapsed().as_secs_f64() < 5.0);
}

#[test]
fn bad_gzip() {
    let gz = {
        let mut enc = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
        enc.write_all(&encode_ply(&sample_mesh()).unwrap()).unwrap();
        enc.finish().unwrap()
    };
    assert_eq!(parse_ply(&gz).unwrap(), sample_mesh());
    assert!(matches!(
        err_kind(&gz[..gz.len() / 2]),
        PlyErrorKind::Gzip(_)
    ));
    let path = temp_path("plain-named.ply.gz");
    std::fs::write(&path, encode_ply(&sample_mesh()).unwrap()).unwrap();
    let e = read_ply(&path).unwrap_err();
    std::fs::remove_file(&path).unwrap();
    assert!(matches!(e.kind, PlyErrorKind::Gzip(_)), "{e}");
}

struct XorShift(u64);
impl XorShift {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

#[test]
fn mutation_fuzz_never_panics() {
    let mut rng = XorShift(0x9e37_79b9_7f4a_7c15);
    let seeds = [
        rich_file(Format::Ascii),
        rich_file(Format::BinaryLittleEndian),
        rich_file(Format::BinaryBigEndian),
        encode_ply(&sample_mesh()).unwrap(),
        {
            let mut enc = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
            enc.write_all(&rich_file(Format::BinaryLittleEndian))
                .unwrap();
            enc.finish().unwrap()
        },
    ];
    let mut ok = 0;
    for iter in 0..6000 {
        let mut bytes = seeds[iter % seeds.len()].clone();
        for _ in 0..1 + rng.below(4) {
            let header_len = bytes
                .windows(10)
                .position(|w| w == b"end_header")
                .unwrap_or(bytes.len());
            match rng.below(6) {
                // Flip a byte anywhere.
                0 | 1 => {
                    let i = rng.below(bytes.len());
                    bytes[i] ^= 1 << rng.below(8);
                }
                // Replace a byte in the header with a digit or space.
                2 => {
                    let i = rng.below(header_len);
                    bytes[i] = b"0123456789 9\n"[rng.below(13)];
                }
                // Random byte in the body.
                3 => {
                    if header_len < bytes.len() {
                        let i = header_len + rng.below(bytes.len() - header_len);
                        bytes[i] = rng.next() as u8;
                    }
                }
                // Truncate.
                4 => {
                    let n = rng.below(bytes.len());
                    bytes.truncate(n.max(1));
                }
                // Insert digits into a header count.
                _ => {
                    let i = rng.below(header_len);
                    for _ in 0..rng.below(12) {
                        bytes.insert(i, b'9');
                    }
                }
            }
        }
        if let Ok(m) = parse_ply(&bytes) {
            ok += 1;
            let nv = m.positions.len() as u32;
            assert!(m.tri_indices.iter().chain(&m.quad_indices).all(|&i| i < nv));
            assert!(m.normals.is_empty() || m.normals.len() == m.positions.len());
            assert!(m.uvs.is_empty() || m.uvs.len() == m.positions.len());
            assert_eq!(m.tri_indices.len() % 3, 0);
            assert_eq!(m.quad_indices.len() % 4, 0);
        }
    }
    // Some mutations (e.g. of float payloads) leave the file valid.
    assert!(ok > 100, "{ok}");
}

fn shared_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/scenes")
}

#[test]
fn real_scene_files_if_present() {
    let dirs = [
        "water-caustic/models",
        "caustic-glass/geometry",
        "killeroos/geometry",
    ];
    let mut checked = 0;
    for dir in dirs {
        let Ok(entries) = std::fs::read_dir(shared_dir().join(dir)) else {
            continue;
        };
        for entry in entries.flatten() {
            let path = entry.path();
            let name = path.to_string_lossy().to_string();
            if !(name.ends_with(".ply") || name.ends_with(".ply.gz")) {
                continue;
            }
            let m = read_ply(&path).unwrap_or_else(|e| panic!("{e}"));
            assert!(!m.positions.is_empty(), "{name}");
            assert!(m.triangle_count() + m.quad_count() > 0, "{name}");
            assert!(m.warnings.is_empty(), "{name}: {:?}", m.warnings);
            for n in &m.normals {
                let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
                assert!((len - 1.0).abs() < 1e-2 || len == 0.0, "{name}: {n:?}");
            }
            assert_eq!(parse_ply(&encode_ply(&m).unwrap()).unwrap(), m, "{name}");
            checked += 1;
        }
    }
    let mesh001 = shared_dir().join("water-caustic/models/Mesh001.ply");
    if mesh001.exists() {
        let m = read_ply(&mesh001).unwrap();
        assert_eq!(m.positions.len(), 63768);
        assert_eq!(m.normals.len(), 63768);
        assert_eq!(m.uvs.len(), 63768);
        assert_eq!(m.triangle_count(), 102938);
    }
    eprintln!("checked {checked} shared PLY files");
}

/// Parses `bytes` through a reader with `window`-byte refills and no known
/// size, the way files and gzip streams are read.
fn parse_windowed(bytes: &[u8], window: usize) -> Result<PlyMesh, String> {
    read::parse_reader(
        std::io::BufReader::with_capacity(window, bytes),
        None,
        false,
        &crate::budget::MemoryBudget::default(),
    )
    .map_err(|k| format!("{k:?}"))
}

#[test]
fn small_windows_read_the_same_as_memory() {
    let mut files: Vec<Vec<u8>> = FORMATS.iter().map(|&f| rich_file(f)).collect();
    let mut odd = sample_mesh();
    odd.face_indices.clear();
    files.push(encode_ply(&odd).unwrap());
    for bytes in &files {
        let whole = parse_ply(bytes).map_err(|e| format!("{:?}", e.kind));
        for window in [1, 2, 3, 5, 7, 13, 16, 64, 1 << 16] {
            assert_eq!(parse_windowed(bytes, window), whole, "window {window}");
        }
        let header_len = bytes
            .windows(11)
            .position(|w| w == b"end_header\n")
            .unwrap()
            + 11;
        for cut in header_len..bytes.len() {
            let whole = parse_ply(&bytes[..cut]).map_err(|e| format!("{:?}", e.kind));
            for window in [1, 4, 9] {
                assert_eq!(
                    parse_windowed(&bytes[..cut], window),
                    whole,
                    "cut {cut} window {window}"
                );
            }
        }
    }
}

#[test]
fn gzip_files_stream_with_the_same_errors() {
    let bytes = encode_ply(&sample_mesh()).unwrap();
    let gz = {
        let mut enc = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
        enc.write_all(&bytes).unwrap();
        enc.finish().unwrap()
    };
    let path = temp_path("stream.ply.gz");
    std::fs::write(&path, &gz).unwrap();
    assert_eq!(read_ply(&path).unwrap(), sample_mesh());
    // Every cut of the compressed stream is a gzip error, never a panic or a
    // PLY truncation.
    for cut in 0..gz.len() {
        std::fs::write(&path, &gz[..cut]).unwrap();
        match read_ply(&path) {
            Err(PlyError {
                kind: PlyErrorKind::Gzip(_),
                ..
            }) => {}
            other => panic!("cut {cut}: {other:?}"),
        }
    }
    std::fs::remove_file(&path).unwrap();
}

#[test]
fn unused_properties_and_elements_are_named_in_one_warning() {
    let text = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nproperty float confidence\nproperty uchar red\nelement face 1\nproperty list uchar int vertex_indices\nproperty int flags\nelement material 1\nproperty float shininess\nend_header\n0 0 0 0.5 1\n1 0 0 0.5 1\n0 1 0 0.5 1\n3 0 1 2 7\n2.5\n";
    let m = super::parse_ply(text.as_bytes()).expect("mesh");
    assert_eq!(m.tri_indices, vec![0, 1, 2]);
    let w: Vec<&String> = m.warnings.iter().filter(|w| w.contains("unused")).collect();
    assert_eq!(w.len(), 1, "{:?}", m.warnings);
    assert!(
        w[0].contains("vertex.confidence, vertex.red, face.flags, element \"material\""),
        "{}",
        w[0]
    );
}

/// Issue 34, finding 6: a mesh past the memory budget is an error naming
/// the budget, whether its header's counts say so or its polygons only
/// grow past it as the gzip stream inflates.
#[test]
fn oom_ply_past_the_budget_is_an_error_not_an_allocation() {
    let budget = |mib: u64| crate::budget::MemoryBudget::labelled(mib << 20, "--max-memory");
    let gzip = |parts: &[&[u8]], repeat_last: usize| {
        let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
        for p in parts {
            gz.write_all(p).unwrap();
        }
        for _ in 1..repeat_last {
            gz.write_all(parts[parts.len() - 1]).unwrap();
        }
        gz.finish().unwrap()
    };
    let xyz = "property float x\nproperty float y\nproperty float z\n";
    let faces = "property list uchar int vertex_indices\n";
    // The header claims 2^24 vertices (192 MiB): refused before the body.
    let header = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex 16777216\n{xyz}\
         element face 0\n{faces}end_header\n"
    );
    let b = budget(16);
    let e = parse_ply_within(&gzip(&[header.as_bytes()], 1), &b).unwrap_err();
    assert_eq!(
        e.to_string(),
        "<memory>: this mesh (16777216 vertices, 0 faces) needs 192.0 MiB; --max-memory is 16.0 MiB"
    );
    assert_eq!(b.used(), 0);
    // 20000 faces of 255 vertices (12 bytes each by the header's count)
    // fan into five million triangles as they are read.
    let header = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex 255\n{xyz}\
         element face 20000\n{faces}end_header\n"
    );
    let vertices = vec![0u8; 255 * 12];
    let mut face = vec![255u8];
    for i in 0..255i32 {
        face.extend(i.to_le_bytes());
    }
    let bytes = gzip(&[header.as_bytes(), &vertices, &face], 20000);
    let b = budget(16);
    let e = parse_ply_within(&bytes, &b).unwrap_err();
    assert!(matches!(e.kind, PlyErrorKind::OverBudget(_)), "{e}");
    let msg = e.to_string();
    assert!(
        msg.starts_with("<memory>: this mesh needs more than ")
            && msg.ends_with(" MiB; --max-memory is 16.0 MiB"),
        "{msg}"
    );
    // What the mesh had charged is given back.
    assert_eq!(b.used(), 0);
    // With room, it is read, and what it holds stays charged.
    let b = budget(256);
    let m = parse_ply_within(&bytes, &b).unwrap();
    assert_eq!(m.triangle_count(), 20000 * 253);
    assert!(b.used() >= (m.tri_indices.len() * 4) as u64);
}
