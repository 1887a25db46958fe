"""Boxes beyond one GPU texture: bricks, each with its own visual, composed by depth."""
