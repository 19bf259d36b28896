pub const BUILTIN_NAMES: &[&str] = &[]; pub fn builtin(_n:&str)->Option<crate::Scene>{None}
