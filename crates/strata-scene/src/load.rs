pub fn load_path(p:&std::path::Path)->Result<crate::Scene,crate::SceneError>{Err(crate::SceneError::file(p,"todo"))}
