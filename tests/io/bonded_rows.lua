-- A scene shared by tests/io/render_series.lua and tests/lua/events.lua:
-- two rows of ten bonded balls pulled apart, so that every bond between
-- the rows breaks in tension (10 cracks) and those within a row hold.
--   local rows = dofile(".../tests/io/bonded_rows.lua"); local m = rows()
return function()
  local m = seixo.model{dim = 3}
  m:material("rock", {kn = 1e6, ks = 1e6, friction = 0.5, density = 2600})
  for i = 0, 9 do
    for j = 0, 1 do m:ball{pos = {0.002 * i, 0.002 * j, 0}, radius = 0.001} end
  end
  m:bond{kind = "parallel", gap = 1e-4, radius_multiplier = 0.5, modulus = 1e7, stiffness_ratio = 2,
         tensile_strength = 1e4, cohesion = 1e4}
  for b in m:balls() do b.vel = {0, b.pos[2] > 0.001 and 0.5 or -0.5, 0} end
  return m
end
