"""Task geometry and success tests: each cell's parameters, hole frame and ground truth."""
