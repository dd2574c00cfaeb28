"""Language models that score how plausible a complete verb frame is (frame- or sentence-linearised)."""
