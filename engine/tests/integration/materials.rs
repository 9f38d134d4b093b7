//! MTL handling, texture de-duplication and the inspect summary.

use crate::common::fixture;
use engine::assets::{load_obj, ColorSpace, TextureCache};

#[test]
fn shared_texture_is_decoded_once() {
    let mut cache = TextureCache::new();
    let model = load_obj(&fixture("textured.obj"), &mut cache).unwrap();
    let (brick, stone) = (&model.materials[0], &model.materials[1]);
    assert_eq!(
        (brick.name.as_str(), stone.name.as_str()),
        ("brick", "stone")
    );
    assert_eq!(brick.maps.base_color, stone.maps.base_color);
    assert_eq!(brick.maps.normal, stone.maps.normal);
    // checker (sRGB), normal (linear), gray (linear) -> 3 decodes for 9 references.
    assert_eq!(cache.decode_count(), 3);
    assert_eq!(cache.len(), 3);

    let checker = cache.get(brick.maps.base_color.unwrap()).unwrap();
    assert_eq!(checker.color_space, ColorSpace::Srgb);
    assert_eq!(
        (checker.width, checker.height, checker.mips.len()),
        (4, 4, 3)
    );
    let gray = brick.maps.roughness.unwrap();
    assert_eq!(brick.maps.metallic, Some(gray));
    assert_eq!(brick.maps.clearcoat, Some(gray));
    assert_eq!(brick.maps.specular, Some(gray));
    assert_eq!(cache.get(gray).unwrap().color_space, ColorSpace::Linear);

    assert_eq!(brick.diffuse, Some([0.8, 0.7, 0.6]));
    assert_eq!(brick.specular, Some([0.1, 0.1, 0.1]));
    assert_eq!(brick.shininess, Some(32.0));
    assert_eq!(model.meshes[0].material, Some(0));
    assert_eq!(model.meshes[1].material, Some(1));

    // Loading again with the same cache decodes nothing new.
    let again = load_obj(&fixture("textured.obj"), &mut cache).unwrap();
    assert_eq!(cache.decode_count(), 3);
    assert_eq!(again.materials[0].maps, brick.maps);
}

#[test]
fn same_file_in_two_color_spaces_is_two_textures() {
    let mut cache = TextureCache::new();
    let a = cache
        .load(&fixture("textures/gray.png"), ColorSpace::Srgb)
        .unwrap();
    let b = cache
        .load(&fixture("textures/gray.png"), ColorSpace::Linear)
        .unwrap();
    let c = cache
        .load(
            &fixture("textures/../textures/gray.png"),
            ColorSpace::Linear,
        )
        .unwrap();
    assert_ne!(a, b);
    assert_eq!(b, c, "canonicalized path dedups");
    assert_eq!(cache.decode_count(), 2);
    assert_eq!(cache.iter().count(), 2);
}

#[test]
fn normal_map_spellings() {
    let mut cache = TextureCache::new();
    let model = load_obj(&fixture("bump_variants.obj"), &mut cache).unwrap();
    let normal = cache
        .load(&fixture("textures/normal.png"), ColorSpace::Linear)
        .unwrap();
    for m in &model.materials {
        assert_eq!(m.maps.normal, Some(normal), "material {}", m.name);
    }
    assert!(
        !model.warnings.iter().any(|w| w.contains(".mtl")),
        "{:?}",
        model.warnings
    );
}

#[test]
fn summary_lists_meshes_materials_textures() {
    let mut cache = TextureCache::new();
    let model = load_obj(&fixture("textured.obj"), &mut cache).unwrap();
    let s = model.summary(&cache);
    assert_eq!(s.meshes.len(), 2);
    assert_eq!(s.meshes[0].name, "first");
    assert_eq!(s.meshes[0].triangles, 1);
    assert_eq!(s.meshes[0].material.as_deref(), Some("brick"));
    assert_eq!(s.materials[0].maps.len(), 6);
    assert!(s.materials[0].maps[0].1.ends_with("checker.png"));
    assert_eq!(s.textures.len(), 3);
    assert_eq!(s.textures[0].mips, 3);
    println!("{s:#?}");
}
