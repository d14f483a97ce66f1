"""Scene building: each cell's fixture and held part as MuJoCo bodies of convex pieces."""
