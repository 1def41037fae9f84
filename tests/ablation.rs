//! `rslf ablation` end to end on the smallest suite: one base scene, static plus one slow and one
//! fast direction, at 64x64 px (at 32 px too few cues are imaged for the cue check to judge) with
//! a few steps per stage.

mod common;

use common::rslf_with_env;

#[test]
fn the_ablation_prints_and_writes_the_four_row_table() {
    let root = common::tempdir();
    let config = root.path().join("small.toml");
    std::fs::write(&config, "[stage1]\ngaussians = 300\niterations = 5\nband_height = 16\n[stage2]\niterations = 3\nbands_per_step = 1\n")
        .unwrap();
    let out = root.path().join("ablation");
    let (ok, stdout, stderr) = rslf_with_env(
        &["ablation", config.to_str().unwrap(), "--size", "64", "--bases", "objects", "--directions", "1", "--out", out.to_str().unwrap()],
        &[("RSLF_CACHE_DIR", &root.path().join("cache"))],
    );
    assert!(ok, "{stderr}");
    assert!(stdout.contains("ablation: 3 scenes x 4 variants at 64x64 px"), "{stdout}");
    // The cue check's verdict under each run that fits a motion (3 scenes x 2 variants).
    assert_eq!(stdout.matches(" check: ").count(), 6, "{stdout}");
    // And the verdict on the fit with the cues under each check that leaves the motion to it
    // (four at this size: both fitting variants of the still and the slow scene).
    let second_chances = stdout.lines().filter(|l| l.contains(" check: ") && l.ends_with("stands clear of their scatter")).count();
    assert!(second_chances > 0, "{stdout}");
    assert_eq!(stdout.matches(" second fit: ").count(), second_chances, "{stdout}");
    let table = std::fs::read_to_string(out.join("ablation.md")).unwrap();
    assert!(stdout.contains(&table), "the printed table is the written one");
    let rows: Vec<&str> = table.lines().skip(2).take(4).collect();
    let names: Vec<&str> = rows.iter().map(|r| r.split('|').nth(1).unwrap().trim()).collect();
    assert_eq!(names, ["no init, no motion", "no motion", "no init", "full"]);
    for row in &rows {
        let cells: Vec<f64> = row.split('|').skip(2).filter(|c| !c.trim().is_empty()).map(|c| c.trim().parse().unwrap()).collect();
        assert_eq!(cells.len(), 6, "{row}");
        assert!(cells.iter().all(|v| v.is_finite() && *v >= 0.0), "{row}");
    }
    // The second table: BadPix(0.07) for every variant, motion errors only where stage 2 ran.
    let second: Vec<&str> = table.lines().skip(9).collect();
    assert_eq!(second.len(), 4, "{table}");
    for (row, name) in second.iter().zip(names) {
        let cells: Vec<&str> = row.split('|').skip(2).map(str::trim).filter(|c| !c.is_empty()).collect();
        assert_eq!(cells.len(), 8, "{row}");
        assert!(cells[..3].iter().all(|c| c.parse::<f64>().is_ok_and(|v| (0.0..=100.0).contains(&v))), "{row}");
        let with_motion = name == "no init" || name == "full";
        assert!(cells[3..].iter().all(|c| c.parse::<f64>().is_ok() == with_motion), "{row}");
    }
    let csv = std::fs::read_to_string(out.join("ablation.csv")).unwrap();
    assert_eq!(csv.lines().count(), 1 + 3 * 4, "{csv}");
    // Only the variants with stage 2 estimate a motion.
    for line in csv.lines().skip(1) {
        let fields: Vec<&str> = line.split(',').collect();
        let moving_variant = fields[2] == "no init" || fields[2] == "full";
        assert_eq!(!fields[6].is_empty(), moving_variant, "{line}");
        assert_eq!(!fields[7].is_empty(), moving_variant, "{line}");
    }
    // The result folders are there for inspection.
    assert!(out.join("objects_static/full/central.png").exists());
}
