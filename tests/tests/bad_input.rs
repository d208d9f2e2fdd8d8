//! smoke
#[test]
fn smoke() {
    let r = pushbot_tests::run_bin("pushbot", &["--bogus"]);
    assert_eq!(r.code, Some(2), "{r:?}");
}
