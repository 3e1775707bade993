//! Reading back the VTK files a run writes, as text: the values of an
//! array, the frames a `.pvd` lists, the pieces a `.pvtp` lists. Plain std,
//! so the command-line tests include this file too (their `common`).

/// The whitespace-separated values of the VTK array `name` in `xml`.
pub fn vtk_tokens<'a>(xml: &'a str, name: &str) -> Vec<&'a str> {
    let at = xml
        .find(&format!("Name=\"{name}\""))
        .unwrap_or_else(|| panic!("array {name} missing"));
    let body = &xml[at..];
    let open = body.find('>').unwrap() + 1;
    let close = body.find("</DataArray>").unwrap();
    body[open..close].split_whitespace().collect()
}

/// The frame files a `.pvd` collection lists (relative to its folder), in
/// time order.
pub fn pvd_files(pvd: &str) -> Vec<&str> {
    attribute_values(pvd, "file")
}

/// The piece files a `.pvtp` lists (relative to its folder), in rank order.
pub fn pvtp_sources(pvtp: &str) -> Vec<&str> {
    attribute_values(pvtp, "Source")
}

/// Every value of the XML attribute `name` in `xml`, in document order.
fn attribute_values<'a>(xml: &'a str, name: &str) -> Vec<&'a str> {
    xml.split(&format!("{name}=\""))
        .skip(1)
        .map(|s| &s[..s.find('"').unwrap()])
        .collect()
}
