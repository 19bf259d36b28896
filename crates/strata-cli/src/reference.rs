//! `strata reference` and `strata bench reference` (filled in once strata-reference lands).

use anyhow::Result;

use crate::args::{BenchReferenceArgs, ReferenceArgs};

pub fn run(_a: &ReferenceArgs) -> Result<()> {
    anyhow::bail!("not yet wired")
}

pub fn bench(_a: &BenchReferenceArgs) -> Result<()> {
    anyhow::bail!("not yet wired")
}
