"""Model reduction: Craig-Bampton CMS, interface reduction (GSI, multi-stage), cyclic
symmetry and damping of reduced models."""
