// Everything a user's build script needs: generate the models in `models/`
// into OUT_DIR, print the errors if there are any.
fn main() {
    println!("cargo::rerun-if-changed=models");
    let out = std::path::PathBuf::from(std::env::var_os("OUT_DIR").expect("run by cargo"));
    if let Err(errors) = dalembert_codegen::compile_dir("models".as_ref(), &out) {
        for e in errors {
            eprintln!("{}", e.render());
        }
        std::process::exit(1);
    }
}
