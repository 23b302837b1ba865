"""Structure cards shipped with bayesfo (one TOML file per structure family)."""
