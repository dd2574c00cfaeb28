-- the most plausible rated frames of each verb (valid ratings only)
with ranked as (
    select *, row_number() over (partition by verb order by mean desc, n desc, arg1, arg2) as rank
    from frame_ratings
)
select verb, rank, role1, arg1, role2, arg2, round(mean, 2) as mean, n
from ranked
where rank <= 5
order by verb, rank
