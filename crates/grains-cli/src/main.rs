fn main() {
    println!("grains {}", env!("CARGO_PKG_VERSION"));
}
