-- seixo.genesis: Potyondy & Cundall's (2004) genesis steps 2 and 3, which
-- seixo.lab's specimens (a vessel of walls) and seixo.periodic's (the
-- periodic cell held still) share; used by those modules, not a user's.
-- A vessel v: v.stress() (its mean direct stress, compression positive),
-- v.volume(), v.gaps(x) (the distances from x to its walls, each {gap,
-- unit normal into the vessel}), v.place(x) (x as the vessel holds it: a
-- periodic cell wraps it) and v.cell ({min, size}: a periodic cell; nil).
local genesis = {}

-- Potyondy & Cundall's (2004) genesis of a specimen of balls, after the
-- compaction by radius expansion (their step 1) to a porosity below the one
-- the packing jams at, so that it starts above sigma0 everywhere: step 2
-- installs sigma0 by scaling every radius by one factor, the vessel held
-- still, and step 3 grows the floaters until each has the contacts it needs.

-- A specimen's sizes: opts.radius = {rmin, rmax} (default dflt, drawn
-- uniformly) or opts.psd, a grading curve as m:generate takes it (which
-- checks it in full). Returns the range {rmin, rmax} and m:generate's
-- fields for the sizes.
function genesis.sizes(opts, fn, dflt)
  local psd = opts.psd
  if psd == nil then
    local radius = opts.radius or dflt
    if type(radius) ~= "table" or #radius ~= 2 or not (radius[1] > 0) or not (radius[2] >= radius[1]) then
      error(string.format("%s: radius must be {rmin, rmax} with 0 < rmin <= rmax", fn), 2)
    end
    return radius, {radius = radius}
  end
  if opts.radius ~= nil then error(string.format("%s: give radius or psd, not both", fn), 2) end
  local first, last = type(psd) == "table" and psd[1], type(psd) == "table" and psd[#psd]
  if type(psd) ~= "table" or #psd < 2 or type(first) ~= "table" or type(last) ~= "table" or not (type(first[1]) == "number" and first[1] > 0)
     or not (type(last[1]) == "number" and last[1] >= first[1]) then
    error(string.format("%s: psd must be a grading curve {{r1, 0}, ..., {rn, 1}} (radius in m, fraction of the volume "
                        .. "passing)", fn), 2)
  end
  return {first[1], last[1]}, {psd = psd}
end

-- The mean overlap of the ball-ball contacts that carry a force, and their number.
function genesis.loaded_contacts(m)
  local overlap, k = 0, 0
  for c in m:contacts{kind = "ball-ball"} do
    if c.fn > 0 then overlap, k = overlap + c.overlap, k + 1 end
  end
  return k > 0 and overlap / k or 0, k
end

-- P&C's step 2: sigma0, the mean direct stress on the walls, by scaling
-- every radius by one factor 1 + eps a stage, the walls held still (the
-- vessel keeps its size, so the specimen keeps the size asked for). eps
-- comes from the packing's stiffness against a uniform growth of the radii,
-- d sigma / d eps = sum over contacts of kn d^2 / (dim V) (each overlap grows
-- by d eps, its force by kn d eps, 4-6, and sigma = sum F d / (dim V)),
-- times a gain: near sigma0 a packing rearranges rather than compresses and
-- is softer than that, so the gain doubles while the error keeps its sign
-- and falls by less than a tenth a stage, and halves (to 1 at least) when
-- it changes sign. A stage cycles 400 steps and then averages the stress
-- over 4 x 100 more: with 200-step stages and no wait, a frictional 2D
-- packing of 4,055 balls swung between 0.5 and 1.35 sigma0 for 30,000
-- steps (its response lags the radii); so it converges within 2 % in 3 to
-- 8 stages. eps is at most 0.5 %; a packing without contacts grows by
-- 0.2 %. Done when two stages in a row are within `tol` of sigma0. Returns
-- the steps, the stress and whether it converged.
local function install_sigma0(m, v, sigma0, opts)
  local dim, start, sigma, gain, last, within = m:dim(), m:step(), 0, 1, nil, 0
  while m:step() - start < opts.max_steps do
    sigma = 0
    m:cycle(400)
    for _ = 1, 4 do
      m:cycle(100)
      sigma = sigma + v.stress() / 4
    end
    local err = sigma0 - sigma
    within = math.abs(err) < opts.tol * sigma0 and within + 1 or 0
    if within >= 2 then return m:step() - start, sigma, true end
    if last and err * last < 0 then gain = math.max(1, gain / 2)
    elseif last and math.abs(err) > 0.9 * math.abs(last) then gain = 2 * gain end
    last = err
    local stiff = 0
    for c in m:contacts{kind = "ball-ball"} do
      if c.overlap > 0 then
        local d = c.a.radius + c.b.radius - c.overlap
        stiff = stiff + c.kn * d * d
      end
    end
    stiff = stiff / (dim * v.volume())
    local eps = stiff > 0 and gain * err / stiff or 0.002
    eps = math.max(-0.005, math.min(0.005, eps))
    for b in m:balls() do b.radius = b.radius * (1 + eps) end
  end
  return m:step() - start, sigma, false
end

-- The balls of m in a cell grid of cells of size h: near(p) lists the
-- entries {ball, pos, radius} in the 3^dim cells about p (every ball whose
-- centre is within h of p), a ball entered where the vessel v holds it
-- (v.place). In a periodic cell (v.cell: {min, size}) a ball is entered
-- again as each image within h of the cell's faces (pos shifted by the
-- cell's edges), so near(p) of a p in the cell sees its neighbours across
-- the faces; put(ball, x, r) moves a ball's entries with it.
local function ball_grid(m, h, v)
  local dim, cells, entries, cell = m:dim(), {}, {}, v.cell
  local function key(p, off)
    local k = 0
    for j = 1, dim do k = k * 1048576 + (math.floor(p[j] / h) + (off and off[j] or 0)) % 1048576 end
    return k
  end
  local function enter(b, p, shift)
    local k = key(p)
    local list = cells[k]
    if not list then list = {}; cells[k] = list end
    local e = {ball = b, pos = p, radius = b.radius, shift = shift}
    list[#list + 1] = e
    local mine = entries[b.id] -- (a ball's handles are equal, not the same value: keyed by id)
    if not mine then mine = {}; entries[b.id] = mine end
    mine[#mine + 1] = e
  end
  local offsets = {} -- -1, 0 or +1 along each axis
  for i = 0, 3 ^ dim - 1 do
    local off, q = {}, i
    for j = 1, dim do off[j] = q % 3 - 1; q = q // 3 end
    offsets[#offsets + 1] = off
  end
  for b in m:balls() do
    local p = v.place(b.pos)
    if not cell then
      enter(b, p)
    else -- the images, by -1, 0, +1 edges along each axis, that lie within h of the cell
      for _, off in ipairs(offsets) do
        local x, shift, inside = {}, {}, true
        for j = 1, dim do
          shift[j] = off[j] * cell.size[j]
          x[j] = p[j] + shift[j]
          inside = inside and x[j] >= cell.min[j] - h and x[j] <= cell.min[j] + cell.size[j] + h
        end
        if inside then enter(b, x, shift) end
      end
    end
  end
  local function near(p)
    local list = {}
    for _, off in ipairs(offsets) do
      for _, e in ipairs(cells[key(p, off)] or {}) do list[#list + 1] = e end
    end
    return list
  end
  local function put(b, x, r)
    for _, e in ipairs(entries[b.id] or {}) do
      local y = {}
      for j = 1, dim do y[j] = x[j] + (e.shift and e.shift[j] or 0) end
      e.pos, e.radius = y, r
    end
  end
  return near, put
end

-- How many neighbours each ball has (by id): the balls and walls of the
-- vessel v within `gap` of its surface, the pairs that bonds will join. At
-- sigma0 a contact's overlap is about 1e-6 of a radius, less than the
-- balls' vibrations, so the contacts that carry a force at a given step
-- flicker; the bond gap does not.
local function neighbour_counts(m, v, gap)
  local near, counts = ball_grid(m, 2 * m:max("radius") + gap, v), {}
  for b in m:balls() do
    local p, r, n = v.place(b.pos), b.radius, 0
    for _, e in ipairs(near(p)) do
      if e.ball ~= b then
        local d2 = 0
        for j = 1, #p do d2 = d2 + (e.pos[j] - p[j]) ^ 2 end
        if math.sqrt(d2) - r - e.radius < gap then n = n + 1 end
      end
    end
    for _, w in ipairs(v.gaps(p)) do if w[1] - r < gap then n = n + 1 end end
    counts[b.id] = n
  end
  return counts
end

-- The point of the convex hull of the vectors us nearest the origin
-- (Gilbert's algorithm: the steepest ascent of min_j u_j . d is along it,
-- and it is 0 where no direction increases every u_j . d).
local function min_norm(us, dim)
  local z = {table.unpack(us[1])}
  for _ = 1, 100 do
    local best, v = math.huge, nil
    for _, u in ipairs(us) do
      local d = 0
      for j = 1, dim do d = d + z[j] * u[j] end
      if d < best then best, v = d, u end
    end
    local zz, dz = 0, 0
    for j = 1, dim do zz, dz = zz + z[j] * z[j], dz + (z[j] - v[j]) ^ 2 end
    if zz - best < 1e-12 or dz == 0 then break end
    local t = math.min(1, (zz - best) / dz)
    for j = 1, dim do z[j] = z[j] + t * (v[j] - z[j]) end
  end
  return z
end

-- The largest ball that fits in the cage of a floater: the centre x that
-- maximises the room min_j (|x - c_j| - r_j) among the balls `near` (and
-- the vessel's walls, vessel.gaps), by steepest ascent of that minimum
-- from p, with steps from r / 4 halving to 1e-7 r. Returns x and the room.
local function fit_in_cage(p, r, near, vessel)
  local dim = #p
  local function constraints(x)
    local list = vessel.gaps(x)
    for _, e in ipairs(near) do
      local u, d2 = {}, 0
      for j = 1, dim do u[j] = x[j] - e.pos[j]; d2 = d2 + u[j] * u[j] end
      local d = math.sqrt(d2)
      if d > 0 then
        for j = 1, dim do u[j] = u[j] / d end
        list[#list + 1] = {d - e.radius, u}
      end
    end
    return list
  end
  local function room(list)
    local g = math.huge
    for _, c in ipairs(list) do g = math.min(g, c[1]) end
    return g
  end
  local x, step = {table.unpack(p)}, 0.25 * r
  local list = constraints(x)
  local best = room(list)
  while step > 1e-7 * r do
    local active = {}
    for _, c in ipairs(list) do if c[1] <= best + step then active[#active + 1] = c[2] end end
    local d = min_norm(active, dim)
    local n = 0
    for j = 1, dim do n = n + d[j] * d[j] end
    n = math.sqrt(n)
    local moved = false
    if n > 1e-9 then
      local y = {}
      for j = 1, dim do y[j] = x[j] + step * d[j] / n end
      local ylist = constraints(y)
      local g = room(ylist)
      if g > best then x, list, best, moved = y, ylist, g, true end
    end
    if not moved then step = 0.5 * step end
  end
  return x, best
end

-- P&C's step 3: a floater, a ball with fewer than nf neighbours (within
-- the bond gap, see neighbour_counts), carries nothing and bonds to
-- little. Each one is moved and grown
-- to the largest ball its cage of neighbours holds, plus the mean overlap
-- of the loaded contacts (so its new contacts carry about the stress of the
-- others): that ball touches dim + 1 neighbours (or walls). Growing it in
-- place instead, to reach its third neighbour, wedged it between the nearer
-- ones: 2D, 408 balls, the stress rose to 1.5e8 Pa, 1,500 sigma0, and the
-- specimen burst its bonds when the vessel went. The packing then cycles
-- 100 steps and the floaters are counted again, by passes, at most
-- max_passes. Returns the floaters found, those left, the passes and the
-- largest relative growth of a radius.
local function eliminate_floaters(m, v, nf, gap, max_passes)
  local found, left, passes, growth = nil, 0, 0, 0
  for pass = 1, max_passes + 1 do
    local counts, overlap = neighbour_counts(m, v, gap), genesis.loaded_contacts(m)
    local floaters = {}
    for b in m:balls() do if (counts[b.id] or 0) < nf then floaters[#floaters + 1] = b end end
    found, left = found or #floaters, #floaters
    if left == 0 or pass > max_passes then break end
    passes = pass
    local near, put = ball_grid(m, 4 * m:max("radius"), v)
    for _, f in ipairs(floaters) do
      local p, r = v.place(f.pos), f.radius
      local cage = {}
      for _, e in ipairs(near(p)) do if e.ball ~= f then cage[#cage + 1] = e end end
      local x, room = fit_in_cage(p, r, cage, v)
      f.pos, f.radius, f.vel = x, room + overlap, #x == 3 and {0, 0, 0} or {0, 0}
      growth = math.max(growth, (room + overlap) / r - 1)
      put(f, x, room + overlap)
    end
    m:cycle(100)
  end
  return found, left, passes, growth
end

-- P&C's steps 2 and 3 on the balls in the vessel v (walls, or a periodic
-- cell: genesis.periodic), after their expansion, frictionless: sigma0
-- by radius scaling and the floaters grown, by rounds, the rock's material
-- mat back in between. Adds to gen (floaters, passes, growth, warnings),
-- logs through say(fmt, ...) (the caller's, with its name); returns the
-- floaters left.
function genesis.steps(m, v, mat, sigma0, gap, opts, gen, say)
  -- sigma0 and the floaters, P&C's steps 2 and 3 (see install_sigma0 and
  -- eliminate_floaters), by rounds: a floater's new contacts load its
  -- neighbours a little, the next round's sigma0 unloads them, which may
  -- leave a ball with too few again (1 or 2 of 4,055 in 2D). The
  -- frictionless unloading stops at 10 sigma0 (within 50 %): a
  -- frictionless packing at sigma0 sits within sigma0 / E, about 2e-6, of
  -- the packing fraction at which it jams, and that fraction drifts by
  -- more as the balls creep, so its stress wanders by tens of per cent and
  -- never settles (2D, 408 balls: between 0.67 and 1.1 sigma0 for 25,000
  -- steps, the ratio at 0.03 to 0.1; 4,075 balls: 0.64 sigma0 after
  -- 30,000). The rock's friction then freezes the packing, 10 sigma0 being
  -- an overlap of 1e-5 of a radius: unloading to sigma0 changes the
  -- packing no more than that.
  local tol, nf, max_steps = opts.sigma0_tol or 0.02, opts.floater_contacts or 3, opts.max_steps or 30000
  local steps, sigma = install_sigma0(m, v, 10 * sigma0, {tol = 0.5, max_steps = max_steps})
  say("frictionless, radii scaled to a stress of %.4g Pa (%d steps)", sigma, steps)
  m:material("rock", mat)
  local ok
  for round = 1, 3 do
    steps, sigma, ok = install_sigma0(m, v, sigma0, {tol = tol, max_steps = max_steps})
    local found, left, passes, growth = eliminate_floaters(m, v, nf, gap, 10)
    say("round %d: sigma0 by radius scaling: %.4g Pa (%d steps), porosity %.4f; floaters "
        .. "(fewer than %d neighbours): %d found, %d left after %d passes (largest growth %.1f %%)", round, sigma,
        steps, 1 - m:sum("volume") / v.volume(), nf, found, left, passes, 100 * growth)
    gen.floaters_found = gen.floaters_found + found
    gen.floater_passes = gen.floater_passes + passes
    gen.floater_growth = math.max(gen.floater_growth, growth)
    if found == 0 then break end
  end
  if not ok then
    gen.warnings[#gen.warnings + 1] = string.format("sigma0 = %.4g Pa missed: %.4g Pa (%.1f %%, tolerance %g %%) "
      .. "after %d steps; raise max_steps", sigma0, sigma, 100 * (sigma / sigma0 - 1), 100 * tol, steps)
  end
  local counts = neighbour_counts(m, v, gap)
  local floaters = 0
  for b in m:balls() do if (counts[b.id] or 0) < nf then floaters = floaters + 1 end end
  if floaters > 0 then
    gen.warnings[#gen.warnings + 1] = string.format("%d floaters left (fewer than %d neighbours within the bond "
      .. "gap)", floaters, nf)
  end
  for _, w in ipairs(gen.warnings) do say("warning: %s", w) end
  return floaters
end

-- Potyondy & Cundall's steps 2 and 3 in a periodic cell (seixo.periodic's
-- genesis, after its expansion), as lab.specimen makes them in its vessel:
-- the cell held still is the vessel (its stress the mean of the cell's
-- direct stresses, no wall to touch), and a floater's cage takes in the
-- images across the faces. Returns the floaters left and gen.
function genesis.periodic(m, mat, sigma0, gap, opts, say)
  local dim, c = m:dim(), m:periodic()
  local cell = {min = c.min, size = c.size}
  local v = {cell = cell, gaps = function() return {} end}
  function v.place(x)
    local p = {}
    for j = 1, dim do p[j] = cell.min[j] + (x[j] - cell.min[j]) % cell.size[j] end
    return p
  end
  function v.stress()
    local s, mean = m:cell_stress(), 0
    for k = 1, dim do mean = mean + s[k][k] / dim end
    return mean
  end
  function v.volume()
    local vol = 1
    for k = 1, dim do vol = vol * cell.size[k] end
    return vol
  end
  local gen = {floaters_found = 0, floater_passes = 0, floater_growth = 0, warnings = {}}
  return genesis.steps(m, v, mat, sigma0, gap, opts, gen, say), gen
end

return genesis
