//! `cargo bench`: the engine benchmark (hang4 at 11, 21, 41, 81 particles a side with every solver),
//! printed as a Markdown table. The same table as `drapelab bench`.

fn main() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let scene = drapelab::scene::Scene::load(&root.join("datasets/scenes/hang4.toml"), &[])
        .expect("bundled scene")
        .scene;
    let rows = drapelab::benchmark::hang4_rows(&scene, &[11, 21, 41, 81], 21, 41, 1e-6, |m| {
        eprintln!("{m}")
    });
    println!("{}", drapelab::benchmark::markdown_table(&rows));
}
