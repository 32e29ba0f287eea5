-- An unforced bed for the MPI tests (mpi_energy guard, mpi_caught): columns
-- of balls of D dimensions, nx by ny by nz (2D: nx by ny), resting on each
-- other a little apart sideways in a fixed box under gravity, their radii
-- varied by a fixed pattern. The model is returned, not cycled.
--   local m = dofile(dir .. "mpi_stack.lua")(dim, nx, ny, nz)
return function(dim, nx, ny, nz)
  local m = seixo.model{dim = dim, gravity = dim == 3 and {0, 0, -9.81} or {0, -9.81}}
  m:material("bead", {density = 2500, kn = 1e8, ks = 1e8, friction = 0.5, damping = 0.1})
  local r = 2e-3
  if dim == 2 then nz = 1 end
  m:wall{kind = "box", min = dim == 3 and {0, 0, 0} or {0, 0},
         max = dim == 3 and {2 * nx * r, 2 * ny * r, 4 * nz * r} or {2 * nx * r, 4 * ny * r}}
  for k = 0, nz - 1 do
    for j = 0, ny - 1 do
      for i = 0, nx - 1 do
        local x = (2 * i + 1) * r
        m:ball{pos = dim == 3 and {x, (2 * j + 1) * r, (2 * k + 1) * r * 1.001} or {x, (2 * j + 1) * r * 1.001},
               radius = r * (1 - 0.05 * ((i * 5 + j * 11 + k * 3) % 7) / 7)}
      end
    end
  end
  return m
end
