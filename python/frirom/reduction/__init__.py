"""Model reduction: eigen-solves, Craig-Bampton CMS, interface reduction."""
