-- Bulk removal: about 20k of 100k cycled balls go in one call, which the
-- core does in one pass over the contacts. The contacts between the balls
-- that stay are untouched, those of the removed balls are gone with their
-- extras, and the model cycles on. A callback's queued removals go the same way.
local T = dofile((debug.getinfo(1, "S").source:match("^@(.*/)") or "./") .. "harness.lua")
local test, check, eq = T.test, T.check, T.eq

-- 100k balls in a hex lattice in a box, pressed by gravity for a few steps
local function packed()
  local m = seixo.model{dim = 2, gravity = {0, -9.81}}
  m:material("s", {density = 2650, kn = 1e7, ks = 1e7, friction = 0.5, damping = 0.7})
  m:wall{kind = "box", min = {0, 0}, max = {0.632, 0.6}}
  local n = m:generate{packing = "hex", radius = 1e-3, region = {box = {{0, 0}, {0.632, 0.55}}}}
  m:cycle(20)
  return m, n
end

-- The contacts by their entities (ball-ball ends ordered by id): fn,
-- overlap and the shear force expressed on the larger id.
local function contacts(m)
  local t, n = {}, 0
  for c in m:contacts() do
    local a, b, fs = c.a.id, c.b.id, c.fs
    local key, balls
    if c.kind == "ball-wall" then
      key, balls = a .. "|w" .. b, {a}
    elseif a < b then
      key, balls = a .. "|" .. b, {a, b}
    else
      key, balls = b .. "|" .. a, {b, a}
      fs = {-fs[1], -fs[2]}
    end
    t[key] = {c.fn, c.overlap, fs[1], fs[2], balls = balls}
    n = n + 1
  end
  return t, n
end

local function same(x, y)
  for k = 1, 4 do
    if x[k] ~= y[k] then return false end
  end
  return true
end

test("remove_balls: 20k of 100k at once", function()
  local m, n = packed()
  check(n > 99000, "the lattice")
  local bottom = {box = {{0, 0}, {0.632, 0.11}}}
  local doomed = {}
  for b in m:balls{region = bottom} do doomed[b.id] = true end
  local before, nbefore = contacts(m)
  check(nbefore > 50000, "contacts before: " .. nbefore)
  -- extras of a removed ball and of a kept one
  local gone_ball, kept_ball = next(doomed), nil
  for b in m:balls() do
    if not doomed[b.id] then kept_ball = b break end
  end
  m:ball(gone_ball):set_extra("tag", "gone")
  kept_ball:set_extra("tag", "kept")
  local handle = m:ball(gone_ball)

  local expected = m:count{region = bottom}
  check(expected > 19000 and expected < 21000, "about 20k selected: " .. expected)
  eq(m:remove_balls{region = bottom}, expected)
  eq(m:ball_count(), n - expected)
  eq(m:count{region = bottom}, 0)
  check(tostring(handle):find("(removed)", 1, true), "the handle knows")
  T.raises(function() return handle.pos end, "has been removed")
  eq(kept_ball:get_extra("tag"), "kept")

  local after, nafter = contacts(m)
  local kept = 0
  for key, c in pairs(before) do
    if doomed[c.balls[1]] or doomed[c.balls[2] or 0] then
      eq(after[key], nil, "a contact of a removed ball: " .. key)
    else
      check(after[key] and same(after[key], c), "contact " .. key .. " lost or changed")
      kept = kept + 1
    end
  end
  eq(nafter, kept, "no new contact")
  check(kept < nbefore, "some contacts went")

  -- the model cycles on; a new ball does not inherit a removed one's extras
  m:cycle(10)
  eq(m:ball_count(), n - expected)
  local fresh = m:ball{pos = {0.3, 0.58}, radius = 1e-3}
  eq(fresh:get_extra("tag"), nil)
end)

test("removals queued by a callback go at once after it", function()
  local m, n = packed()
  local top = {box = {{0, 0.5}, {0.632, 0.55}}}
  local expected = m:count{region = top}
  check(expected > 1000, "the top rows")
  local seen
  m:on("cycle", function()
    if seen then return end
    seen = {m:remove_balls{region = top}, m:ball_count()}
  end, {every = 5})
  m:cycle(5)
  eq(seen[1], expected)
  eq(seen[2], n, "queued while the callback runs")
  eq(m:ball_count(), n - expected)
  -- (reading the id of a removed ball's handle raises)
  local _, nc = contacts(m)
  check(nc > 50000, "the contacts of the rest")
  m:cycle(5)
end)

T.done()
