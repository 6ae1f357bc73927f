//! A process that ends at once (a second Ctrl-C) removes the files it was still writing.
//! Alone in its test binary: the list of files being written is the process's.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)] // test code

use master::output::{give_up_unfinished, write_unfinished};

fn temporary_files(dir: &std::path::Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .filter(|n| n.starts_with(master::output::UNFINISHED_PREFIX))
        .collect()
}

#[test]
fn files_being_written_are_removed_when_the_process_gives_up() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("r.csv");
    std::fs::write(&path, "earlier results\n").unwrap();
    // written in full but not committed: a temporary file until committed or dropped
    let file = write_unfinished(&path, |w| {
        w.write_all(b"new results\n").unwrap();
        Ok(())
    })
    .unwrap();
    assert_eq!(temporary_files(dir.path()).len(), 1);
    file.commit().unwrap();
    assert!(temporary_files(dir.path()).is_empty());
    assert_eq!(std::fs::read_to_string(&path).unwrap(), "new results\n");
    let dropped = write_unfinished(&dir.path().join("s.json"), |w| {
        w.write_all(b"{}").unwrap();
        Ok(())
    })
    .unwrap();
    drop(dropped);
    assert!(temporary_files(dir.path()).is_empty());
    // interrupted while writing: the temporary file goes, the earlier results stay
    let written = write_unfinished(&path, |w| {
        w.write_all(b"half of the newest ").unwrap();
        assert_eq!(temporary_files(dir.path()).len(), 1);
        give_up_unfinished();
        assert!(temporary_files(dir.path()).is_empty());
        Ok(())
    });
    if let Ok(file) = written {
        assert!(file.commit().is_err(), "renamed a removed file");
    }
    assert_eq!(std::fs::read_to_string(&path).unwrap(), "new results\n");
    // and no file is begun after that (a worker thread still writing)
    let e = write_unfinished(&path, |_| Ok(())).err().unwrap();
    assert!(e.to_string().contains("the process is ending"), "{e}");
    assert!(temporary_files(dir.path()).is_empty());
    assert_eq!(std::fs::read_to_string(&path).unwrap(), "new results\n");
}
