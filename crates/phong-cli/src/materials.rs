//! `phong materials`: the built-in materials, or one of them.

use crate::InputError;
use anyhow::Result;
use phong_core::{Material, named_materials};

/// A colour as three numbers.
pub fn fmt3(c: phong_core::Color) -> String {
    format!("{:.6} {:.6} {:.6}", c.r, c.g, c.b)
}

/// Lists the materials, or shows `name`.
pub fn materials(name: Option<&str>) -> Result<()> {
    match name {
        None => {
            println!(
                "{:<16} {:<27} {:<27} {:<27} {:>5} {:>9}",
                "name", "ambient", "diffuse", "specular", "alpha", "shininess"
            );
            for m in named_materials() {
                let v = &m.material;
                println!(
                    "{:<16} {:<27} {:<27} {:<27} {:>5} {:>9}",
                    m.name,
                    fmt3(v.ambient()),
                    fmt3(v.diffuse()),
                    fmt3(v.specular()),
                    v.alpha(),
                    v.shininess()
                );
            }
        }
        Some(n) => {
            let m = Material::named(n).map_err(|e| InputError(e.to_string()))?;
            let canonical = named_materials().iter().find(|x| x.material == m).map_or(n, |x| x.name);
            println!("{canonical}");
            println!("  ambient   {}", fmt3(m.ambient()));
            println!("  diffuse   {}", fmt3(m.diffuse()));
            println!("  specular  {}", fmt3(m.specular()));
            println!("  emission  {}", fmt3(m.emission()));
            println!("  shininess {}", m.shininess());
            println!("  alpha     {}", m.alpha());
        }
    }
    Ok(())
}
