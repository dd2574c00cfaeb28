-- workers: assignments, ratings, rejections and the mean absolute difference to the other raters
with others as (
    select v.worker_id, v.rating,
           (f.mean * f.n - v.rating) / nullif(f.n - 1, 0) as others_mean
    from valid_ratings v
    join frame_ratings f using (verb, role1, arg1, role2, arg2)
),
counts as (
    select worker_id, count(distinct assignment_id) as assignments, count(*) as ratings,
           count(distinct assignment_id) filter (where status = 'Rejected') as rejected
    from ratings join assignments using (assignment_id)
    group by worker_id
)
select c.*, round(avg(abs(o.rating - o.others_mean)), 3) as mean_abs_diff_to_others
from counts c
left join others o using (worker_id)
group by all
order by rejected desc, mean_abs_diff_to_others desc
