fn main() {
    println!("luxeval");
}
