//! Parse throughput on a large generated scene of inline triangle meshes.
//! Run with `cargo bench -p rpbrt-parser`; prints MB/s.

use std::fmt::Write as _;
use std::time::Instant;

use rpbrt_parser::{parse_string, FileLoc, ParamList, ParserTarget};

/// Counts values so the parse cannot be optimized away.
#[derive(Default)]
struct Count {
    values: usize,
}

macro_rules! ignore {
    ($($name:ident($($arg:ident: $ty:ty),*);)*) => {
        $(fn $name(&mut self, $($arg: $ty,)* _loc: FileLoc) -> rpbrt_parser::DirectiveResult {
            $(let _ = $arg;)*
            Ok(())
        })*
    };
}

impl ParserTarget for Count {
    ignore! {
        identity(); translate(d: [f32; 3]); scale(s: [f32; 3]); rotate(a: f32, x: [f32; 3]);
        look_at(e: [f32; 3], l: [f32; 3], u: [f32; 3]); concat_transform(m: [f32; 16]);
        transform(m: [f32; 16]); coordinate_system(n: &str); coord_sys_transform(n: &str);
        active_transform_all(); active_transform_end_time(); active_transform_start_time();
        transform_times(s: f32, e: f32); reverse_orientation(); color_space(n: &str);
        pixel_filter(n: &str, p: ParamList); film(n: &str, p: ParamList); sampler(n: &str, p: ParamList);
        accelerator(n: &str, p: ParamList); integrator(n: &str, p: ParamList); camera(n: &str, p: ParamList);
        make_named_medium(n: &str, p: ParamList); medium_interface(i: &str, o: &str);
        option(n: &str, v: &str); world_begin(); attribute_begin(); attribute_end();
        attribute(t: &str, p: ParamList); texture(n: &str, t: &str, c: &str, p: ParamList);
        material(n: &str, p: ParamList); make_named_material(n: &str, p: ParamList);
        named_material(n: &str); light_source(n: &str, p: ParamList); area_light_source(n: &str, p: ParamList);
        object_begin(n: &str); object_end(); object_instance(n: &str);
        renderer(n: &str, p: ParamList); surface_integrator(n: &str, p: ParamList);
        volume_integrator(n: &str, p: ParamList); volume(n: &str, p: ParamList);
        search_path(n: &str);
    }
    fn shape(&mut self, _n: &str, p: ParamList, _loc: FileLoc) -> rpbrt_parser::DirectiveResult {
        self.values += p.iter().map(|p| p.value_count()).sum::<usize>();
        Ok(())
    }
    fn end_of_files(&mut self) -> rpbrt_parser::DirectiveResult {
        Ok(())
    }
}

fn main() {
    let target_bytes = 200usize << 20;
    let mut text = String::with_capacity(target_bytes + (1 << 20));
    text.push_str("WorldBegin\n");
    let mut x: u32 = 12345;
    let mut rnd = move || {
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        x
    };
    while text.len() < target_bytes {
        text.push_str("AttributeBegin\nShape \"trianglemesh\"\n  \"point3 P\" [\n");
        for _ in 0..3000 {
            let v = (rnd() % 2_000_000) as f32 / 1000.0 - 1000.0;
            let _ = write!(text, "{v} ");
        }
        text.push_str("]\n  \"integer indices\" [\n");
        for i in 0..3000 {
            let _ = write!(text, "{} ", i % 1000);
        }
        text.push_str("]\nAttributeEnd\n");
    }
    let mb = text.len() as f64 / (1024.0 * 1024.0);
    for _ in 0..3 {
        let mut c = Count::default();
        let t = Instant::now();
        let r = parse_string(&text, &mut c);
        let s = t.elapsed().as_secs_f64();
        assert!(r.is_ok());
        println!(
            "parsed {mb:.1} MiB ({} values) in {s:.3}s: {:.0} MiB/s",
            c.values,
            mb / s
        );
    }
}
